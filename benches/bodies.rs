//! Speed of the cell solver on each body (docs/bodies.md) against the ellipsoid's, on slices of
//! the same size: 256 κ-rows in [0.01, 2] × 256 energies ε = V_min(κ) + 4 j/255, j = 1 … 256,
//! so that every cell has motion, tol 1e-10, all outputs, 2 threads, rows shared out by rayon
//! one at a time. The slices run interleaved, seven times each, in one process, so that the
//! ratios are meaningful on a shared machine; prints cells per second (the slices have the
//! same 65,536 cells: the ratio of the times) and components per second (a body with fewer
//! tori per cell has fewer components to solve), median and best of seven, and each body's
//! ratios to the ellipsoid. Besides the ellipsoid and the three edged
//! bodies: two profiles (docs/bodies.md, "Your own body"), the egg of atlas/egg.toml and the
//! truncated ball given as a table of 12 points (the same body as the shape, with more joints).
//! `cargo bench --bench bodies`.

use rayon::prelude::*;
use rubber_atlas::cell::{solve_level, CellOptions};
use rubber_atlas::torus::EffectivePotential;
use rubber_atlas::{Body, EdgedShape, EllipsoidBody, Profile, ProfileShape, Shape};
use std::time::Instant;

/// κ-rows of each slice, and energies per row.
const ROWS: usize = 256;
/// Cells in each slice.
const CELLS: usize = ROWS * ROWS;

/// Components and seconds of one slice of `body`.
fn slice<S: Shape>(
    body: &Body<S>,
    pool: &rayon::ThreadPool,
    options: &CellOptions,
) -> (usize, f64) {
    let n = ROWS;
    let start = Instant::now();
    let components = pool.install(|| {
        (0..n)
            .into_par_iter()
            .with_max_len(1)
            .map(|i| {
                let kappa = 0.01 + 1.99 * i as f64 / (n - 1) as f64;
                let row = EffectivePotential::new(body, kappa);
                let bottom = row.lowest_minimum().expect("κ > 0 has a well");
                (1..=n)
                    .map(|j| {
                        let energy = bottom + 4.0 * j as f64 / (n - 1) as f64;
                        solve_level(&row, energy, options).unwrap().components.len()
                    })
                    .sum::<usize>()
            })
            .sum()
    });
    (components, start.elapsed().as_secs_f64())
}

fn main() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let options = CellOptions {
        tol: 1e-10,
        ..CellOptions::default()
    };
    let ellipsoid = EllipsoidBody::ellipsoid(0.5, 3.0, 0.5, 0.5).unwrap();
    let disk = Body::new(EdgedShape::disk(0.3).unwrap(), 2.0, 4.0).unwrap();
    let ball = Body::new(EdgedShape::truncated_ball(0.2, 0.4).unwrap(), 0.7, 1.3).unwrap();
    let wheel = Body::new(EdgedShape::wheel(0.25, 0.7).unwrap(), 0.7, 1.3).unwrap();
    let egg = [
        [0.0, -1.0, 0.0],
        [0.45, -0.92, 0.0],
        [0.8, -0.62, 0.0],
        [0.98, -0.2, 0.0],
        [0.97, 0.25, 0.0],
        [0.8, 0.62, 1.0],
        [0.4, 0.8, 0.0],
        [0.0, 0.86, 0.0],
    ];
    let profile = |rows: Vec<Vec<f64>>, alpha, nu, eta| {
        let shape = ProfileShape::new(Profile::from_points(&rows).unwrap(), alpha).unwrap();
        Body::new(shape, nu, eta).unwrap()
    };
    let egg = profile(egg.iter().map(|r| r.to_vec()).collect(), -0.1, 0.8, 1.7);
    // The truncated ball (cut 0.4) as a table: its face, the edge, 10 points of the sphere.
    let edge_angle = 0.4f64.acos();
    let mut ball_rows = vec![vec![0.0, -0.4], vec![edge_angle.sin(), -0.4, 1.0]];
    for i in 1..=10 {
        let phi = edge_angle + (std::f64::consts::PI - edge_angle) * i as f64 / 10.0;
        let rho = if i == 10 { 0.0 } else { phi.sin() };
        ball_rows.push(vec![rho, -phi.cos()]);
    }
    let ball_table = profile(ball_rows, 0.2, 0.7, 1.3);
    let names = [
        "ellipsoid (0.5, 3)",
        "disk (0.3)",
        "truncated ball (0.2, 0.4)",
        "wheel (0.25, 0.7)",
        "egg (profile, 8 points)",
        "truncated ball as 12 points",
    ];
    let mut rates: [Vec<f64>; 6] = Default::default();
    let mut cell_rates: [Vec<f64>; 6] = Default::default();
    for _ in 0..7 {
        let runs = [
            slice(&ellipsoid, &pool, &options),
            slice(&disk, &pool, &options),
            slice(&ball, &pool, &options),
            slice(&wheel, &pool, &options),
            slice(&egg, &pool, &options),
            slice(&ball_table, &pool, &options),
        ];
        for ((rate, cell_rate), (components, seconds)) in
            rates.iter_mut().zip(cell_rates.iter_mut()).zip(runs)
        {
            rate.push(components as f64 / seconds);
            cell_rate.push(CELLS as f64 / seconds);
        }
    }
    let stats = |r: &mut Vec<f64>| {
        r.sort_by(f64::total_cmp);
        (r[r.len() / 2], r[r.len() - 1])
    };
    for (what, rates) in [("cells", &mut cell_rates), ("components", &mut rates)] {
        let summary: Vec<(f64, f64)> = rates.iter_mut().map(stats).collect();
        println!("{what} per second, 2 threads, tol 1e-10, all outputs (median, best of 7):");
        for (name, (median, best)) in names.iter().zip(&summary) {
            println!(
                "  {name:<28} {median:>9.0} {best:>9.0}   ratio to the ellipsoid {:.2} (median), {:.2} (best)",
                median / summary[0].0,
                best / summary[0].1
            );
        }
    }
}
