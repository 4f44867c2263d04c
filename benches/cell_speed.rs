//! Speed of the cell solver on the standard slice of docs/accuracy.md: α = 0.5, β = 3, ν = η = 0.5,
//! κ ∈ [0, 2] × ε ∈ [0.5, 4.5] on 256 × 256 cells, tol 1e-10, rows of fixed κ shared out by
//! rayon one row at a time (rows differ in cost several-fold: with rayon's default splitting
//! one thread idles at the end, 200k/s instead of 245k/s). Two output sets: all outputs (the
//! the figure of docs/accuracy.md) and N alone (T, ω_θ, ω_ψ, N without the drift integrals, what a scene that
//! asks for no drift computes, and what the NumPy comparison script computes). Prints
//! cell-components per second for 1 and 2 threads, the median and the best of seven runs of
//! each, interleaved in one process so that the ratio is meaningful on a shared machine (other
//! load only ever slows a run down, so the best run is the machine's capacity and the median
//! what a user sees). Then the price of accuracy (issue 23): the same slice, each output set,
//! 2 threads, at tol 1e-10, 1e-12, 1e-13 and 1e-14, seven interleaved runs each: the median
//! time, its ratio to 1e-10's and the components `ok`. `cargo bench --bench cell_speed`.

use rayon::prelude::*;
use rubber_atlas::cell::{solve_level, CellOptions};
use rubber_atlas::torus::EffectivePotential;
use rubber_atlas::EllipsoidBody;
use std::time::Instant;

fn slice(threads: usize, options: &CellOptions) -> (usize, usize, f64) {
    let body = EllipsoidBody::ellipsoid(0.5, 3.0, 0.5, 0.5).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let n = 256;
    let start = Instant::now();
    let (components, not_ok) = pool.install(|| {
        (0..n)
            .into_par_iter()
            .with_max_len(1)
            .map(|i| {
                let kappa = 2.0 * i as f64 / (n - 1) as f64;
                let row = EffectivePotential::new(&body, kappa);
                let mut count = (0, 0);
                for j in 0..n {
                    let energy = 0.5 + 4.0 * j as f64 / (n - 1) as f64;
                    let cell = solve_level(&row, energy, options).unwrap();
                    count.0 += cell.components.len();
                    count.1 += cell
                        .components
                        .iter()
                        .filter(|c| c.status != rubber_atlas::cell::Status::Ok)
                        .count();
                }
                count
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
    });
    (components, not_ok, start.elapsed().as_secs_f64())
}

fn main() {
    for (outputs, drift) in [("all outputs", true), ("N alone", false)] {
        let options = CellOptions {
            tol: 1e-10,
            drift,
            ..CellOptions::default()
        };
        let mut seconds = [Vec::new(), Vec::new()];
        let mut counts = (0, 0);
        for _ in 0..7 {
            for (threads, times) in [1, 2].into_iter().zip(seconds.iter_mut()) {
                let (components, not_ok, elapsed) = slice(threads, &options);
                counts = (components, not_ok);
                times.push(elapsed);
            }
        }
        let (components, not_ok) = counts;
        for (threads, times) in [1, 2].into_iter().zip(seconds.iter_mut()) {
            times.sort_by(f64::total_cmp);
            let (median, best) = (times[times.len() / 2], times[0]);
            println!(
                "{outputs}, threads {threads}: {components} cell-components in {median:.3} s \
                 (median of 7) = {:.0} per second, best {:.0} per second ({not_ok} not ok)",
                components as f64 / median,
                components as f64 / best
            );
        }
    }
    let tolerances = [1e-10, 1e-12, 1e-13, 1e-14];
    for (outputs, drift) in [("all outputs", true), ("N alone", false)] {
        let mut seconds = vec![Vec::new(); tolerances.len()];
        let mut counts = vec![(0, 0); tolerances.len()];
        for _ in 0..7 {
            for (i, &tol) in tolerances.iter().enumerate() {
                let options = CellOptions {
                    tol,
                    drift,
                    ..CellOptions::default()
                };
                let (components, not_ok, elapsed) = slice(2, &options);
                counts[i] = (components, not_ok);
                seconds[i].push(elapsed);
            }
        }
        let median = |times: &mut Vec<f64>| {
            times.sort_by(f64::total_cmp);
            times[times.len() / 2]
        };
        let base = median(&mut seconds[0]);
        for ((tol, times), (components, not_ok)) in tolerances.iter().zip(&mut seconds).zip(counts)
        {
            let time = median(times);
            println!(
                "{outputs}, 2 threads, tol {tol:e}: {time:.3} s (median of 7), {:.2} x tol 1e-10, \
                 {} of {components} ok ({:.2} %)",
                time / base,
                components - not_ok,
                100.0 * (components - not_ok) as f64 / components as f64
            );
        }
    }
}
