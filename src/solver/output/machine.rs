//! The machine a run or a benchmark ran on, part of its provenance: wall times and
//! throughput only compare within one kind of host (one CPU family and model), and the same
//! source runs its pair loops on different vector widths from host to host
//! (`target-cpu=native`).

use serde::{Deserialize, Serialize};

/// The CPU a result was computed on and what the binary made of it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// CPU vendor (`GenuineIntel`, `AuthenticAMD`; empty off x86-64).
    pub cpu_vendor: String,
    /// CPU brand string (virtual machines often give a generic one, hence the numbers).
    pub cpu_brand: String,
    /// CPU family and model, as Linux's `/proc/cpuinfo` numbers them (0 off x86-64).
    pub cpu_family: u32,
    /// See `cpu_family`.
    pub cpu_model: u32,
    /// Logical CPUs the process may use.
    pub logical_cpus: usize,
    /// The widest vector extension the binary was compiled for: `avx512f`, `avx2` or
    /// `baseline`.
    pub compiled_simd: String,
    /// The path the neighbour lists' distance test takes on this CPU.
    pub distance_test: String,
}

impl Machine {
    /// This machine, as this binary runs on it.
    pub fn detect() -> Self {
        let (cpu_vendor, cpu_brand, cpu_family, cpu_model) = cpu();
        Self {
            cpu_vendor,
            cpu_brand,
            cpu_family,
            cpu_model,
            logical_cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
            compiled_simd: compiled_simd().into(),
            distance_test: crate::solver::nnps::DistanceTest::fastest().name().into(),
        }
    }

    /// The kind of CPU: `GenuineIntel family 6 model 207 (Intel(R) Xeon(R) Processor)`, or
    /// `not recorded` for results written before it was.
    pub fn cpu(&self) -> String {
        if *self == Self::default() {
            return "not recorded".into();
        }
        let brand = if self.cpu_brand.is_empty() { String::new() } else { format!(" ({})", self.cpu_brand) };
        let vendor = if self.cpu_vendor.is_empty() { "unknown CPU" } else { &self.cpu_vendor };
        format!("{vendor} family {} model {}{brand}", self.cpu_family, self.cpu_model)
    }

    /// One line for a table's title: `GenuineIntel family 6 model 207 (Intel(R) Xeon(R)
    /// Processor), 2 logical CPUs, compiled for avx512f, distance test avx512`.
    pub fn describe(&self) -> String {
        format!(
            "{}, {} logical CPUs, compiled for {}, distance test {}",
            self.cpu(),
            self.logical_cpus,
            self.compiled_simd,
            self.distance_test
        )
    }
}

fn compiled_simd() -> &'static str {
    if cfg!(target_feature = "avx512f") {
        "avx512f"
    } else if cfg!(target_feature = "avx2") {
        "avx2"
    } else {
        "baseline"
    }
}

/// Family and model from CPUID leaf 1's EAX, as Linux and the vendors' manuals combine the
/// base and extended fields: the extended family is added to family 15 only, the extended
/// model prefixed for families 6 and 15 and above.
pub fn family_model(eax: u32) -> (u32, u32) {
    let base_family = (eax >> 8) & 0xf;
    let family = if base_family == 0xf { base_family + ((eax >> 20) & 0xff) } else { base_family };
    let model = (eax >> 4) & 0xf;
    let model =
        if base_family == 6 || base_family == 0xf { model | (((eax >> 16) & 0xf) << 4) } else { model };
    (family, model)
}

#[cfg(target_arch = "x86_64")]
fn cpu() -> (String, String, u32, u32) {
    use std::arch::x86_64::__cpuid;
    let text = |regs: &[u32]| -> String {
        let bytes: Vec<u8> = regs.iter().flat_map(|r| r.to_le_bytes()).collect();
        String::from_utf8_lossy(&bytes).trim_matches(char::from(0)).trim().to_string()
    };
    let leaf0 = __cpuid(0);
    let vendor = text(&[leaf0.ebx, leaf0.edx, leaf0.ecx]);
    let (family, model) = if leaf0.eax >= 1 { family_model(__cpuid(1).eax) } else { (0, 0) };
    let brand = if __cpuid(0x8000_0000).eax >= 0x8000_0004 {
        let regs: Vec<u32> = (0x8000_0002..=0x8000_0004u32)
            .flat_map(|leaf| {
                let r = __cpuid(leaf);
                [r.eax, r.ebx, r.ecx, r.edx]
            })
            .collect();
        text(&regs)
    } else {
        String::new()
    };
    (vendor, brand, family, model)
}

#[cfg(not(target_arch = "x86_64"))]
fn cpu() -> (String, String, u32, u32) {
    (String::new(), String::new(), 0, 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The signatures of some hosts' CPUs (stepping 0).
    #[test]
    fn family_and_model_combine_the_extended_fields() {
        assert_eq!(family_model(0x000c_06f0), (6, 207), "Intel Xeon (Sapphire Rapids)");
        assert_eq!(family_model(0x00a0_0f10), (25, 1), "AMD Zen 3");
        assert_eq!(family_model(0x00a1_0f10), (25, 17), "AMD Zen 4");
        assert_eq!(family_model(0x00b0_0f20), (26, 2), "AMD Zen 5");
        // Below family 6 the extended model is not part of the model.
        assert_eq!(family_model(0x0001_0520), (5, 2));
    }

    #[test]
    fn this_host_is_described() {
        let h = Machine::detect();
        assert!(h.logical_cpus >= 1);
        assert!(["avx512", "avx2", "portable"].contains(&h.distance_test.as_str()));
        if cfg!(target_arch = "x86_64") {
            assert!(!h.cpu_vendor.is_empty() && h.cpu_family > 0, "{h:?}");
        }
        let line = h.describe();
        assert!(line.contains(&format!("family {} model {}", h.cpu_family, h.cpu_model)), "{line}");
        assert!(line.contains(&format!("distance test {}", h.distance_test)), "{line}");
        assert_eq!(Machine::default().cpu(), "not recorded");
    }
}
