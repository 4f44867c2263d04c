//! `rubber-atlas run` as a user runs it, on the standard slice of docs/accuracy.md (atlas/standard-slice.toml:
//! α = 0.5, β = 3, κ × ε on 256 × 256 cells, all outputs, tol 1e-10):
//! - cells per second on 1 and on 2 threads (median of 5 runs each, interleaved so that
//!   other load on a shared machine hits both alike), and their ratio (target ≥ 1.8);
//! - the peak resident memory of that run and of a grid 8 times larger in more slices
//!   (8 values of β), read from the kernel's rusage of each child (target: no more than
//!   the standard slice's + 10 %).
//!
//! `cargo bench --bench run_scaling`

use std::path::Path;
use std::process::Command;
use std::time::Instant;

const BIN: &str = env!("CARGO_BIN_EXE_rubber-atlas");

/// Runs the binary; returns (wall seconds, peak RSS in KiB) from wait4's rusage.
fn run(scene: &Path, out: &Path, threads: usize) -> (f64, i64) {
    let start = Instant::now();
    // Reaped below by wait4 (which also gives the child's rusage), not by Child::wait.
    #[allow(clippy::zombie_processes)]
    let child = Command::new(BIN)
        .arg("run")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .args(["--threads", &threads.to_string(), "--force", "--quiet"])
        .spawn()
        .expect("rubber-atlas starts");
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: waits for our own child, which std has not reaped (we never call wait on it).
    let waited = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    let seconds = start.elapsed().as_secs_f64();
    assert_eq!(waited, pid, "wait4 failed");
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "run failed"
    );
    (seconds, usage.ru_maxrss)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let slice = root.join("atlas/standard-slice.toml");
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("eight-slices.toml");
    let text = std::fs::read_to_string(&slice).unwrap();
    assert!(text.contains("beta = [3.0]"));
    std::fs::write(
        &big,
        text.replace("name = \"standard-slice\"", "name = \"eight-slices\"")
            .replace(
                "beta = [3.0]",
                "beta = [2.3, 2.4, 2.5, 2.6, 2.7, 2.8, 2.9, 3.0]",
            ),
    )
    .unwrap();
    let out = dir.path().join("out.h5");
    let cells = 256.0 * 256.0;

    let (mut one, mut two, mut rss_slice) = (Vec::new(), Vec::new(), 0);
    run(&slice, &out, 2); // warm the page cache
    for _ in 0..5 {
        let (t1, m1) = run(&slice, &out, 1);
        let (t2, m2) = run(&slice, &out, 2);
        one.push(t1);
        two.push(t2);
        rss_slice = rss_slice.max(m1).max(m2);
    }
    let (t1, t2) = (median(one), median(two));
    println!(
        "standard slice ({cells} cells, whole run: compute, journal, HDF5): 1 thread {:.3} s = \
         {:.0} cells/s; 2 threads {:.3} s = {:.0} cells/s; ratio {:.2} (target >= 1.8)",
        t1,
        cells / t1,
        t2,
        cells / t2,
        t1 / t2
    );
    let (mut rss_big, mut t_big) = (0, Vec::new());
    for _ in 0..2 {
        let (t, m) = run(&big, &out, 2);
        rss_big = rss_big.max(m);
        t_big.push(t);
    }
    println!(
        "peak resident memory: standard slice {:.1} MiB, 8 slices (8x the cells) {:.1} MiB = \
         {:.1} % of the slice's (target <= 110 %); 8 slices on 2 threads in {:.2} s",
        rss_slice as f64 / 1024.0,
        rss_big as f64 / 1024.0,
        100.0 * rss_big as f64 / rss_slice as f64,
        median(t_big)
    );
}
