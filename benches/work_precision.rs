//! Work-precision study of the cell solver (issue 3): for tolerances 1e-4 … 1e-13 and both
//! methods, the time per cell and the error in N and T on four classes of cells — regular,
//! near a separatrix (1e-3 and 1e-6 from the top of V), very near it (1e-9 and 1e-12) and
//! small κ (1e-2 … 1e-6) — against the
//! 40-digit values of `benches/work_precision_cells.csv` (scripts/work_precision_truth.py).
//! Time per cell is for all the cell's components, with the row's critical points found
//! beforehand (as in an atlas, where a row of cells shares them).
//! Writes docs/work-precision.csv; scripts/plot_work_precision.py draws it.
//! `cargo bench --bench work_precision`.

use rubber_atlas::cell::{solve_level, CellOptions, ComponentResult, Method};
use rubber_atlas::torus::EffectivePotential;
use rubber_atlas::EllipsoidBody;
use std::path::Path;
use std::time::Instant;

/// A row of `benches/work_precision_cells.csv`: a cell and its 40-digit truth.
#[derive(serde::Deserialize)]
struct Truth {
    class: String,
    alpha: f64,
    beta: f64,
    kappa: f64,
    energy: f64,
    theta: f64,
    period: f64,
    rotation_number: f64,
}

struct Cell {
    class: String,
    body: EllipsoidBody,
    kappa: f64,
    energy: f64,
    theta: f64,
    period: f64,
    rotation_number: f64,
}

fn read_cells(path: &Path) -> Vec<Cell> {
    let mut reader =
        csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    reader
        .deserialize::<Truth>()
        .map(|row| {
            let t = row.unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            Cell {
                class: t.class,
                body: EllipsoidBody::ellipsoid(t.alpha, t.beta, 0.5, 0.5).expect("a valid body"),
                kappa: t.kappa,
                energy: t.energy,
                theta: t.theta,
                period: t.period,
                rotation_number: t.rotation_number,
            }
        })
        .collect()
}

/// The component of a solved cell that holds (or lies nearest to) θ.
fn component_at(components: &[ComponentResult], theta: f64) -> &ComponentResult {
    let distance = |c: &ComponentResult| (c.theta_min - theta).max(theta - c.theta_max).max(0.0);
    components
        .iter()
        .min_by(|a, b| distance(a).total_cmp(&distance(b)))
        .expect("a cell of the study has motion")
}

/// A row of docs/work-precision.csv.
#[derive(serde::Serialize)]
struct Row {
    class: String,
    method: &'static str,
    tol: f64,
    cells: usize,
    seconds_per_cell: f64,
    #[serde(rename = "max_abs_error_n")]
    max_error_n: f64,
    #[serde(rename = "max_error_estimate_n")]
    max_estimate_n: f64,
    #[serde(rename = "max_rel_error_t")]
    max_relative_error_t: f64,
    #[serde(rename = "dishonest_cells")]
    dishonest: usize,
    #[serde(rename = "mean_work")]
    work: f64,
}

fn measure(cells: &[&Cell], method: Method, tol: f64) -> (f64, f64, f64, f64, usize, f64) {
    let options = CellOptions {
        tol,
        method,
        ..CellOptions::default()
    };
    // The critical points of V belong to the row (α, β, κ) and are shared by all its cells
    // in an atlas: they are found once, outside the timing.
    let rows: Vec<EffectivePotential<'_, _>> = cells
        .iter()
        .map(|c| EffectivePotential::new(&c.body, c.kappa))
        .collect();
    // Accuracy from one pass, time from as many passes as fill 50 ms.
    let (mut max_error, mut max_estimate, mut max_t, mut dishonest, mut work) =
        (0.0f64, 0.0f64, 0.0f64, 0, 0.0);
    for (cell, row) in cells.iter().zip(&rows) {
        let solved = solve_level(row, cell.energy, &options).expect("solves");
        let c = component_at(&solved.components, cell.theta);
        let error = (c.rotation_number - cell.rotation_number).abs();
        let t_error = (c.period - cell.period).abs();
        max_error = max_error.max(error);
        max_estimate = max_estimate.max(c.errors.rotation_number);
        max_t = max_t.max(t_error / cell.period);
        // The 40-digit truth is exact at this scale: an estimate below the error is dishonest.
        if error > c.errors.rotation_number || t_error > c.errors.period {
            dishonest += 1;
        }
        work += c.work as f64 / cells.len() as f64;
    }
    let start = Instant::now();
    let mut passes = 0;
    while passes == 0 || start.elapsed().as_secs_f64() < 0.05 {
        for (cell, row) in cells.iter().zip(&rows) {
            std::hint::black_box(solve_level(row, cell.energy, &options).ok());
        }
        passes += 1;
    }
    let per_cell = start.elapsed().as_secs_f64() / (passes * cells.len()) as f64;
    (per_cell, max_error, max_estimate, max_t, dishonest, work)
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cells = read_cells(&root.join("benches/work_precision_cells.csv"));
    let tolerances: Vec<f64> = (4..=13).map(|k| 10f64.powi(-k)).collect();
    let mut rows = Vec::new();
    for class in ["regular", "separatrix", "separatrix_close", "small_kappa"] {
        let members: Vec<&Cell> = cells.iter().filter(|c| c.class == class).collect();
        for (method, name) in [(Method::Quadrature, "quadrature"), (Method::Ode, "ode")] {
            for &tol in &tolerances {
                let (per_cell, max_error_n, max_estimate_n, max_t, dishonest, work) =
                    measure(&members, method, tol);
                rows.push(Row {
                    class: class.to_string(),
                    method: name,
                    tol,
                    cells: members.len(),
                    seconds_per_cell: per_cell,
                    max_error_n,
                    max_estimate_n,
                    max_relative_error_t: max_t,
                    dishonest,
                    work,
                });
                println!(
                    "{class:12} {name:10} tol {tol:7.0e}: {:9.2} µs/cell  |ΔN| ≤ {max_error_n:8.1e} \
                     (estimate {max_estimate_n:8.1e})  |ΔT|/T ≤ {max_t:8.1e}  work {work:6.0}  \
                     dishonest {dishonest}",
                    per_cell * 1e6
                );
            }
        }
    }
    let out = root.join("docs/work-precision.csv");
    let mut writer =
        csv::Writer::from_path(&out).unwrap_or_else(|e| panic!("{}: {e}", out.display()));
    for r in &rows {
        writer
            .serialize(r)
            .unwrap_or_else(|e| panic!("{}: {e}", out.display()));
    }
    writer
        .flush()
        .unwrap_or_else(|e| panic!("{}: {e}", out.display()));
    println!("wrote {}", out.display());
}
