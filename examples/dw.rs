use rubber_atlas::cell::{solve_level, CellOptions};
use rubber_atlas::torus::EffectivePotential;
use rubber_atlas::{Body, EdgedShape};

fn main() {
    let body = Body::new(EdgedShape::disk(0.3).unwrap(), 2.0, 4.0).unwrap();
    let n = 64;
    let options = CellOptions {
        tol: 1e-10,
        ..CellOptions::default()
    };
    let mut rows = Vec::new();
    for i in 8..16 {
        let kappa = 0.01 + 1.99 * i as f64 / (n - 1) as f64;
        let row = EffectivePotential::new(&body, kappa);
        let bottom = row.lowest_minimum().unwrap();
        let seps = row.separatrix_levels();
        for j in 1..=n {
            let energy = bottom + 4.0 * j as f64 / (n - 1) as f64;
            for c in solve_level(&row, energy, &options).unwrap().components {
                let gap = seps
                    .iter()
                    .map(|s| (energy - s).abs())
                    .fold(f64::INFINITY, f64::min);
                rows.push((
                    c.work,
                    kappa,
                    energy,
                    c.theta_min,
                    c.theta_max,
                    gap,
                    format!("{:?}", c.family),
                ));
            }
        }
    }
    let total: usize = rows.iter().map(|r| r.0).sum();
    println!(
        "mean {:.1} over {}",
        total as f64 / rows.len() as f64,
        rows.len()
    );
    let mut hist = std::collections::BTreeMap::new();
    for r in &rows {
        *hist.entry(r.0).or_insert(0) += 1;
    }
    println!("{:?}", hist);
    rows.sort_by(|a, b| b.0.cmp(&a.0));
    for r in rows.iter().take(12) {
        println!("{:?}", r);
    }
}
