//! Whether a resolution fits before a particle is made: the particle count the neighbour
//! lists index, and the memory the machine (or the process's limit) has.

/// Bytes a particle takes at most in `D` dimensions, with its neighbour list and every
/// scheme's work arrays: in 2D `sphrepro bench` measures 860-1940 (the most at nx = 50, where
/// fixed costs weigh); in 3D, with four times the neighbours, the peak resident size of a
/// 40x40x8 Taylor-Green run is 3.5 kB a particle with SPST and 3.8 kB with IPST.
const fn bytes_per_particle(d: usize) -> f64 {
    if d < 3 {
        2048.0
    } else {
        4096.0
    }
}

/// Refuses a resolution (parameter `key` = `value`) whose `particles` could not run: more
/// than the neighbour lists' 32-bit indices hold, or more memory than this machine has
/// (see `total_memory`). Called before any particle is made, so that a mistyped resolution
/// is a parameter error, not minutes of allocation ending in an abort.
pub fn check_size<const D: usize>(
    scene: &str,
    key: &str,
    value: impl std::fmt::Display,
    particles: f64,
) -> Result<(), String> {
    let refuse =
        |why: String| Err(format!("scene `{scene}`: `{key}` = {value}: {particles:.3e} particles {why}"));
    if particles > u32::MAX as f64 {
        return refuse(format!("are more than the {} a neighbour list indexes", u32::MAX));
    }
    let need = particles * bytes_per_particle(D);
    match total_memory() {
        Some(have) if need > have => refuse(format!(
            "need about {:.1} GiB, more than this machine's {:.1} GiB",
            need / GIB,
            have / GIB
        )),
        _ => Ok(()),
    }
}

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// The memory this process may use in bytes, if the system says (Linux): the machine's
/// physical memory, or a container's limit (cgroup v2) if lower, or what its address-space
/// limit (`ulimit -v`) leaves beyond the address space it already holds, if lower still (an
/// allocation past that limit aborts the process, with no summary).
fn total_memory() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    let limit =
        std::fs::read_to_string("/sys/fs/cgroup/memory.max").ok().and_then(|s| s.trim().parse::<f64>().ok());
    let have = limit.map_or(kib * 1024.0, |l| l.min(kib * 1024.0));
    Some(address_space_left().map_or(have, |left| left.min(have)))
}

/// Bytes of address space left under the process's limit (`RLIMIT_AS`), if it has one.
#[cfg(target_os = "linux")]
fn address_space_left() -> Option<f64> {
    let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: getrlimit writes into the struct it is given.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } != 0 || limit.rlim_cur == libc::RLIM_INFINITY {
        return None;
    }
    // VmSize: the address space the process holds now, in kiB.
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmSize:"))?;
    let held: f64 = line.split_whitespace().nth(1)?.parse::<f64>().ok()? * 1024.0;
    Some((limit.rlim_cur as f64 - held).max(0.0))
}

#[cfg(not(target_os = "linux"))]
fn address_space_left() -> Option<f64> {
    None
}
