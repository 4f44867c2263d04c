//! The integration tests of rubber-atlas, one binary (one link instead of ten): each module
//! tests one part of the pipeline through the public library or the built program.

mod bodies;
mod cell;
mod cli;
mod critical;
mod domain;
mod family;
mod limits;
mod model;
mod plane;
mod profile;
mod resonance;
mod run;
mod units;
mod verdict;

/// How [`h5`] opens a file.
pub enum H5 {
    Create,
    Read,
    ReadWrite,
}

/// An HDF5 file opened by this test process, with HDF5's file locking off. HDF5 opens without
/// O_CLOEXEC and locks with flock, so a program another test spawns while a file is open here
/// inherits the descriptor and keeps the file locked for as long as it runs, even after the
/// file is closed here; the program a test runs next on that file then fails to open it
/// ("unable to lock file, errno = 11"). That made `run::four_shards_merged_equal_a_single_run`
/// and `cli::update_replaces_only_its_own_files` fail now and then (reproduced: a child that
/// slept 3 s held a file closed here locked until it ended).
pub fn h5(path: impl AsRef<std::path::Path>, mode: H5) -> hdf5::File {
    let mut builder = hdf5::File::with_options();
    builder.with_fapl(|p| p.file_locking(false));
    let path = path.as_ref();
    match mode {
        H5::Create => builder.create(path),
        H5::Read => builder.open(path),
        H5::ReadWrite => builder.open_rw(path),
    }
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// How far the full equations carry the centre of mass from `start` on `body` in time
/// `t_end` (an unbounded path runs away n·|Δζ| in n periods).
pub fn full_model_distance<S: rubber_atlas::Shape>(
    body: &rubber_atlas::Body<S>,
    start: &rubber_atlas::trajectory::Start,
    t_end: f64,
) -> f64 {
    use rubber_atlas::trajectory::{integrate, Model};
    let t = integrate(body, start, Model::Full, t_end, 4, 1e-12, &|| false).unwrap();
    let n = t.t.len() - 1;
    (t.x_c[n] - t.x_c[0]).hypot(t.y_c[n] - t.y_c[0])
}

/// A cell of a body symmetric about its equator with three tori, `well_0`, `well_equator`
/// and `well_pi`: the middle one centred on π/2 (to `centre_tol`), the outer two mirror
/// images with opposite N (to `n_tol`).
pub fn assert_mirror_families(cell: &rubber_atlas::cell::CellResult, centre_tol: f64, n_tol: f64) {
    use rubber_atlas::family::Family;
    let families: Vec<Family> = cell.components.iter().map(|c| c.family).collect();
    assert_eq!(
        families,
        [Family::Well0, Family::WellEquator, Family::WellPi],
        "{cell:?}"
    );
    let [lo, mid, hi] = [0, 1, 2].map(|i| &cell.components[i]);
    assert!(
        (mid.theta_min + mid.theta_max - std::f64::consts::PI).abs() < centre_tol,
        "{mid:?}"
    );
    assert!(
        (lo.rotation_number + hi.rotation_number).abs() < n_tol,
        "{lo:?} {hi:?}"
    );
}

/// On the N = 0 resonance curve of `body` in the window κ ∈ `kappa_window`, ε up to
/// `energy_max`, the cell at the curve's first point with κ in `near` has N = 0, is unbounded,
/// its torus crosses `kink`, and the full equations carry the centre of mass n·|Δζ| from its
/// start in n = 5 and 10 periods, to 1e-6.
pub fn assert_a_resonant_cell_runs_away<S: rubber_atlas::Shape>(
    body: &rubber_atlas::Body<S>,
    kappa_window: (f64, f64),
    energy_max: f64,
    near: (f64, f64),
    kink: f64,
) {
    use rubber_atlas::cell::{solve_cell, CellOptions};
    use rubber_atlas::resonance::{trace_curves, ResonanceOptions};
    let options = ResonanceOptions::window(body, 0.0, kappa_window, None, energy_max, 24, 1e-12);
    let curves = trace_curves(body, &options).unwrap();
    let point = curves
        .iter()
        .flat_map(|c| c.points.iter())
        .find(|p| p.kappa > near.0 && p.kappa < near.1)
        .expect("a point of the N = 0 curve in the range of kappa");
    let cell = solve_cell(
        body,
        point.kappa,
        point.energy,
        &CellOptions {
            tol: 1e-12,
            drift: true,
            ..CellOptions::default()
        },
    )
    .unwrap();
    let comp = &cell.components[point.component];
    assert!(comp.rotation_number.abs() <= 1e-9, "{comp:?}");
    assert_eq!(comp.bounded, Some(false), "{comp:?}");
    assert!(
        comp.theta_min < kink && kink < comp.theta_max,
        "{comp:?}: kink {kink}"
    );
    let start = rubber_atlas::trajectory::Start {
        kappa: point.kappa,
        theta0: comp.theta_min,
        theta_dot0: 0.0,
    };
    for periods in [5.0, 10.0] {
        let away = full_model_distance(body, &start, periods * comp.period);
        assert!(
            (away - periods * comp.drift).abs() <= 1e-6 * periods * comp.drift,
            "after {periods} periods the full model is {away} away, expected {}",
            periods * comp.drift
        );
    }
}
