//! The bench report: the Markdown table of every measured configuration (with the peer's
//! columns when it ran), printed with the host it ran on and the targets it has the runs
//! for.

use super::case::{BenchResult, DEFAULT_KERNEL};
use super::peer::{PeerResult, PEER_BASELINE_NX};
use super::stats::{Ratio, Repeated};
use super::targets::{self, TargetRow};
use crate::solver::output::machine::Machine;

/// A throughput in millions, with the range over `runs` when there were several.
fn millions(speed: f64, runs: &[f64]) -> String {
    let lo = runs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = runs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if runs.len() > 1 {
        format!("{:.3} ({:.3}-{:.3})", speed / 1e6, lo / 1e6, hi / 1e6)
    } else {
        format!("{:.3}", speed / 1e6)
    }
}

/// [`Ratio::of`] `a / b`, formatted ([`Ratio::format`]).
fn ratio(a: &impl Repeated, b: &impl Repeated, digits: usize, suffix: &str) -> String {
    Ratio::of(a, b).format(digits, suffix)
}

/// The benchmark table as Markdown (throughput of the median run, with the range over the
/// runs when there were several), with the throughput of each variant relative to
/// `edac` on the same size and threads, and the two-thread speed-up; with peer results, the
/// peer's throughput and our ratio to it on the same size and threads, our ratio to the
/// peer's run at [`PEER_BASELINE_NX`] on the same threads (the targets for the larger sizes
/// are multiples of that run), and both L1 velocity errors at the peer's end time. Ratios
/// of repeated runs are those of each round (see [`Ratio::of`]).
pub(super) fn table(results: &[BenchResult], peers: &[PeerResult]) -> String {
    let mut s = String::from(
        "| variant | nx | particles | threads | steps | Mparticle-steps/s | ns/particle-step | bytes/particle | cost vs edac | speed-up vs 1 thread | IPST iters | step order | time: neighbours/density/pressure/accel/ipst/integrate (%) |",
    );
    if !peers.is_empty() {
        s.push_str(&format!(
            " peer Mparticle-steps/s | ratio to peer | ratio to peer at nx = {PEER_BASELINE_NX} | L1 at the peer's end time: peer / edac (%) |"
        ));
    }
    s.push_str("\n|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    if !peers.is_empty() {
        s.push_str("---|---|---|---|");
    }
    s.push('\n');
    for r in results {
        let edac = results
            .iter()
            .find(|e| e.variant == "edac" && e.nx == r.nx && e.threads == r.threads && e.copies == r.copies);
        let one = results
            .iter()
            .find(|e| e.variant == r.variant && e.nx == r.nx && e.threads == 1 && e.copies == 1);
        let cost = match edac {
            Some(e) if std::ptr::eq(e, r) => "1.00".to_string(),
            Some(e) => ratio(e, r, 2, ""),
            None => String::new(),
        };
        // Of k copies on one thread each, the speed-up the host allows k independent runs.
        let speedup = if r.threads * r.copies > 1 {
            one.map(|o| ratio(r, o, 2, "")).unwrap_or_default()
        } else {
            String::new()
        };
        let p = &r.phase_shares;
        let shares = format!(
            "{:.0}/{:.0}/{:.0}/{:.0}/{:.0}/{:.0}",
            100.0 * p.neighbours,
            100.0 * p.density,
            100.0 * p.pressure,
            100.0 * p.accelerations,
            100.0 * p.ipst,
            100.0 * p.integrate
        );
        let speed = millions(r.particle_steps_per_second, &r.runs);
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {:.0} | {:.0} | {} | {} | {:.2} | {} | {} |\n",
            r.variant,
            r.nx,
            r.particles,
            r.threads_label(),
            r.steps,
            speed,
            1e9 / r.particle_steps_per_second,
            r.bytes_per_particle,
            cost,
            speedup,
            r.ipst_iterations_mean,
            r.schedule,
            shares
        ));
        if !peers.is_empty() {
            match peers.iter().find(|p| p.nx == r.nx && p.threads == r.threads && r.copies == 1) {
                Some(p) => {
                    let pct = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.2}", 100.0 * v));
                    let l1 = if r.variant == "edac" {
                        format!(
                            "{} / {} (t = {:.4})",
                            pct(p.l1_velocity_final),
                            pct(p.sphrepro_l1_velocity_final),
                            p.end_time()
                        )
                    } else {
                        String::new()
                    };
                    let at_50 = peers
                        .iter()
                        .find(|q| q.nx == PEER_BASELINE_NX && q.threads == r.threads)
                        .map_or(String::new(), |q| ratio(r, q, 1, "x"));
                    let to_peer = ratio(r, p, 1, "x");
                    s.insert_str(
                        s.len() - 1,
                        &format!(
                            " {} | {to_peer} | {at_50} | {l1} |",
                            millions(p.particle_steps_per_second, &p.runs)
                        ),
                    )
                }
                None => s.insert_str(s.len() - 1, "  |  |  |  |"),
            }
        }
    }
    for k in results.iter().map(|r| r.copies).filter(|&k| k > 1).collect::<std::collections::BTreeSet<_>>() {
        s.push_str(&format!(
            "\n`{k} x 1`: {k} copies of the case stepped at once, on one thread each, their throughputs \
             summed: their speed-up is what this host gives {k} independent runs, the ceiling of \
             the {k}-thread one.\n"
        ));
    }
    s
}

/// Prints the report on stdout: a title naming the case and the host (throughputs compare
/// only within one kind of host: its CPU model and whether the neighbour search's distance
/// test has a vector path on it), the table, and the targets the runs measured.
pub(super) fn print(
    kernel: &str,
    machine: &Machine,
    results: &[BenchResult],
    peers: &[PeerResult],
    targets: &[TargetRow],
) {
    crate::outln!("Taylor-Green, Re = 100, kernel {kernel}, h/dx = 1, on {}:\n", machine.describe());
    crate::outln!("{}", table(results, peers));
    if !targets.is_empty() {
        // The targets are set for the peer's own run, with its (and the paper's) kernel.
        let caveat = if kernel == DEFAULT_KERNEL {
            String::new()
        } else {
            format!(" (they are set for the {DEFAULT_KERNEL} kernel; this run used {kernel})")
        };
        crate::outln!("Against the throughput targets{caveat}:\n\n{}", targets::table(targets));
    }
}

#[cfg(test)]
mod tests {
    use super::super::peer::parse_peer;
    use super::super::testutil::sample;
    use super::*;

    /// The peer columns: its throughput, our ratio to it, and both L1 errors on edac's row.
    #[test]
    fn the_table_compares_throughput_and_accuracy_with_the_peer() {
        let ours = |variant: &str, speed: f64| sample(variant, 50, 2, speed);
        let out = "{\"particle_steps_per_second\": 3.0e5, \"l1_velocity_final\": 0.02, \"t_final\": 2.0}";
        let mut peer = parse_peer(out, 50, 2, 2.0).unwrap();
        peer.sphrepro_l1_velocity_final = Some(0.0115);
        let t = table(&[ours("edac", 4.5e6), ours("ctvf+sun", 3.0e6)], &[peer.clone()]);
        let rows: Vec<&str> = t.lines().collect();
        assert!(rows[2].ends_with("| 0.300 | 15.0x | 15.0x | 2.00 / 1.15 (t = 2.0000) |"), "{}", rows[2]);
        assert!(rows[3].ends_with("| 0.300 | 10.0x | 10.0x |  |"), "{}", rows[3]);
        // At a larger size the peer is faster (its overhead amortised): the ratio to it
        // there and to its nx = 50 run differ.
        let big = BenchResult { nx: 400, particles: 160_000, ..ours("edac", 5.4e6) };
        let peer_400 = PeerResult { nx: 400, particle_steps_per_second: 9.0e5, ..peer.clone() };
        let t = table(&[ours("edac", 4.5e6), big], &[peer, peer_400]);
        let rows: Vec<&str> = t.lines().collect();
        assert!(rows[3].contains("| 0.900 | 6.0x | 18.0x |"), "{}", rows[3]);
        // Without a peer run at nx = 50 the column is empty.
        let t = table(
            &[BenchResult { nx: 400, ..ours("edac", 5.4e6) }],
            &[PeerResult { nx: 400, ..parse_peer(out, 400, 2, 0.02).unwrap() }],
        );
        assert!(t.lines().nth(2).unwrap().contains("| 0.300 | 18.0x |  |"), "{t}");
    }
}
