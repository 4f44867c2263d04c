//! `rubber-atlas verdict` as a user runs it (the whole process, 2 threads): wall time for one
//! body over the whole (κ, ε) plane, on the bodies of issue 11 and on the corners of the
//! (α, β) domain (target: within 1 s each). Each body runs 3 times; the median and the
//! worst are reported, with the verdict for the record. The map over 40 α × 60 β (target:
//! within 10 minutes) is timed by `scripts/hypothesis.py` itself, which prints it.
//!
//! `cargo bench --bench verdict`

use std::process::Command;
use std::time::Instant;

const BIN: &str = env!("CARGO_BIN_EXE_rubber-atlas");

/// (α, β, ν, η): the paper's type (c), the counterexamples, type (d), type (b), the
/// extremes of the map's range and beyond it.
const BODIES: [(f64, f64, f64, f64); 15] = [
    (0.5, 3.0, 0.5, 0.5),
    (0.5, 0.5, 0.5, 0.5),
    (0.9, 20.0, 0.5, 0.5),
    (0.0, 0.5, 0.5, 0.5),
    (0.5, 1.1, 0.5, 0.5),
    (0.0, 0.05, 0.5, 0.5),
    (0.975, 0.05, 0.5, 0.5),
    (0.5, 50.0, 0.5, 0.5),
    (0.975, 50.0, 0.5, 0.5),
    (0.3, 300.0, 1.0, 1.0),
    (0.999, 300.0, 1.0, 1000.0),
    (1e-6, 3.0, 0.01, 1000.0),
    (0.0, 0.01, 0.5, 0.5),
    (0.5, 0.001, 0.5, 0.5),
    (0.3, 1000.0, 0.5, 0.5),
];

fn main() {
    println!("verdict: one body over the whole plane (wall seconds, 2 threads, 3 runs)");
    println!(
        "{:>8} {:>8} {:>6} {:>7} | {:>7} {:>7} | verdict",
        "alpha", "beta", "nu", "eta", "median", "worst"
    );
    let mut worst_all: f64 = 0.0;
    for (alpha, beta, nu, eta) in BODIES {
        let mut times = Vec::new();
        let mut verdict = String::new();
        for _ in 0..3 {
            let start = Instant::now();
            let out = Command::new(BIN)
                .env("RAYON_NUM_THREADS", "2")
                .args(["verdict", "--json"])
                .arg(format!("--alpha={alpha}"))
                .arg(format!("--beta={beta}"))
                .arg(format!("--nu={nu}"))
                .arg(format!("--eta={eta}"))
                .output()
                .expect("rubber-atlas starts");
            times.push(start.elapsed().as_secs_f64());
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
            verdict = format!(
                "case {} holds {}",
                v["case"].as_str().unwrap_or("?"),
                v["holds"]
            );
        }
        times.sort_by(f64::total_cmp);
        worst_all = worst_all.max(times[2]);
        println!(
            "{alpha:>8} {beta:>8} {nu:>6} {eta:>7} | {:>7.3} {:>7.3} | {verdict}",
            times[1], times[2]
        );
    }
    println!("worst of all: {worst_all:.3} s (target 1 s)");
}
