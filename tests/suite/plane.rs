//! Scenes that cover the (κ, ε) plane without waste (issue 11): log-spaced axes, an energy
//! axis measured from the bottom of V at each κ (`excess_energy`), and the compactified pair
//! (`lambda`, `s`) that reaches ε = ∞ at s = 0. Through the binary: the file's dimensions and
//! its κ, ε per cell (CF auxiliary coordinates), every cell equal to the library's own cell
//! at that κ and ε, the s = 0 column equal to the high-energy limit N∞(λ), and bad planes
//! refused with one line.

use rubber_atlas::cell::{solve_cell, CellOptions};
use rubber_atlas::limits::high_energy_rotation_number;
use rubber_atlas::scene::{Axis, Plane, Scene};
use rubber_atlas::torus::EffectivePotential;
use rubber_atlas::EllipsoidBody;
use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_rubber-atlas");

fn scene(axes: &str) -> String {
    format!(
        "name = \"plane\"\n[body]\nnu = 0.5\neta = 0.5\n[axes]\nalpha = [0.5]\nbeta = [0.5, 3.0]\n{axes}\n\
         [solver]\ntolerance = 1e-10\n[outputs]\nfields = [\"rotation_number\", \"theta_min\", \"status\", \"error_estimate\"]\n"
    )
}

fn run_scene(dir: &Path, axes: &str) -> hdf5::File {
    run_scene_text(dir, &scene(axes))
}

/// Runs a scene given whole, and opens its atlas.
fn run_scene_text(dir: &Path, text: &str) -> hdf5::File {
    let path = dir.join("plane.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("plane.h5");
    let o = Command::new(BIN)
        .args([
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
            "--force",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    crate::h5(out, crate::H5::Read)
}

fn read4(f: &hdf5::File, name: &str) -> ndarray::Array4<f64> {
    f.dataset(name)
        .unwrap()
        .read::<f64, ndarray::Ix4>()
        .unwrap()
}

fn read5(f: &hdf5::File, name: &str) -> ndarray::Array5<f64> {
    f.dataset(name)
        .unwrap()
        .read::<f64, ndarray::Ix5>()
        .unwrap()
}

/// The slot of the component axis (family layout, the default) that holds `family`.
fn slot(f: &hdf5::File, family: rubber_atlas::family::Family) -> usize {
    let labels = f.dataset("component").unwrap().read_raw::<u8>().unwrap();
    labels
        .iter()
        .position(|&c| c == family.code())
        .unwrap_or_else(|| panic!("no slot for {family} in {labels:?}"))
}

fn text_attr(d: &hdf5::Dataset, name: &str) -> String {
    d.attr(name)
        .unwrap()
        .read_scalar::<hdf5::types::VarLenUnicode>()
        .unwrap()
        .as_str()
        .to_string()
}

#[test]
fn log_spacing_hits_both_ends_and_is_geometric() {
    let s = Scene::parse(
        &scene("kappa = { start = 1e-3, stop = 10.0, num = 5, spacing = \"log\" }\nenergy = [1.0, 2.0]"),
        "t.toml",
    )
    .unwrap();
    assert_eq!(s.kappa.values[0], 1e-3);
    assert_eq!(s.kappa.values[4], 10.0);
    for (x, want) in s.kappa.values.iter().zip([1e-3, 1e-2, 1e-1, 1.0, 10.0]) {
        assert!((x / want - 1.0).abs() < 1e-14, "{x} vs {want}");
    }
    assert_eq!(s.plane, Plane::KappaEnergy);
    assert_eq!(Axis::logspace(2.0, 2.0, 1), vec![2.0]);
}

#[test]
fn bad_planes_are_refused_naming_the_key() {
    for (axes, key) in [
        (
            "kappa = [1.0]\nenergy = [1.0]\nexcess_energy = [1.0]",
            "axes",
        ),
        ("kappa = [1.0]", "axes"),
        ("lambda = [0.5]\nenergy = [1.0]", "axes"),
        ("lambda = [-0.5, 0.5]\ns = [0.0, 0.1]", "axes.lambda"),
        ("lambda = [0.5]\ns = [-0.1, 0.1]", "axes.s"),
        (
            "kappa = { start = 0.0, stop = 1.0, num = 3, spacing = \"log\" }\nenergy = [1.0]",
            "axes.kappa.start",
        ),
        (
            "kappa = { start = 0.1, stop = 1.0, num = 3, spacing = \"cubic\" }\nenergy = [1.0]",
            "axes.kappa.spacing",
        ),
    ] {
        let e = Scene::parse(&scene(axes), "t.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&format!("t.toml: {key}:")), "{axes}: {e}");
    }
}

#[test]
fn excess_energy_plane_starts_at_the_bottom_of_every_row() {
    let dir = tempfile::tempdir().unwrap();
    let f = run_scene(
        dir.path(),
        "kappa = { start = 0.01, stop = 3.0, num = 7, spacing = \"log\" }\n\
         excess_energy = { start = 0.0, stop = 4.0, num = 9 }",
    );
    let names: Vec<String> = f.member_names().unwrap();
    for name in ["kappa", "excess_energy", "energy", "rotation_number"] {
        assert!(names.contains(&name.to_string()), "{names:?}");
    }
    assert_eq!(
        text_attr(&f.dataset("rotation_number").unwrap(), "coordinates"),
        "nu eta energy"
    );
    let energy = read4(&f, "energy");
    let n = read5(&f, "rotation_number");
    let kappas = f.dataset("kappa").unwrap().read_raw::<f64>().unwrap();
    let excess = f
        .dataset("excess_energy")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    let status = f
        .dataset("cell_status")
        .unwrap()
        .read::<u8, ndarray::Ix4>()
        .unwrap();
    for (ib, beta) in [0.5, 3.0].into_iter().enumerate() {
        let body = EllipsoidBody::ellipsoid(0.5, beta, 0.5, 0.5).unwrap();
        for (ik, &kappa) in kappas.iter().enumerate() {
            let bottom = EffectivePotential::new(&body, kappa)
                .lowest_minimum()
                .unwrap();
            for (ie, &e) in excess.iter().enumerate() {
                let eps = energy[[0, ib, ik, ie]];
                assert_eq!(eps, bottom + e);
                // Every cell has motion: none is wasted below the bottom.
                assert_eq!(
                    status[[0, ib, ik, ie]],
                    0,
                    "β = {beta}, κ = {kappa}, e = {e}"
                );
                let cell = solve_cell(
                    &body,
                    kappa,
                    eps,
                    &CellOptions {
                        drift: false,
                        ..CellOptions::default()
                    },
                )
                .unwrap();
                let first = &cell.components[0];
                let k = slot(&f, first.family);
                assert_eq!(
                    n[[0, ib, ik, ie, k]].to_bits(),
                    first.rotation_number.to_bits()
                );
            }
        }
    }
}

/// λ = 0 is κ = 0 along the whole s-axis, ε = ∞ included (its κ coordinate was inf there).
#[test]
fn compact_plane_keeps_kappa_zero_at_lambda_zero() {
    let dir = tempfile::tempdir().unwrap();
    let f = run_scene(dir.path(), "lambda = [0.0, 0.5]\ns = [0.0, 0.5]");
    let kappa = read4(&f, "kappa");
    assert_eq!(kappa[[0, 0, 0, 0]], 0.0);
    assert_eq!(kappa[[0, 0, 0, 1]], 0.0);
    assert!(kappa[[0, 0, 1, 0]].is_infinite());
    assert_eq!(kappa[[0, 0, 1, 1]], 1.0);
}

#[test]
fn compact_plane_reaches_infinite_energy_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let f = run_scene(
        dir.path(),
        "lambda = { start = 0.05, stop = 1.4, num = 6 }\ns = { start = 0.0, stop = 0.5, num = 6 }",
    );
    let rn = f.dataset("rotation_number").unwrap();
    assert_eq!(text_attr(&rn, "coordinates"), "nu eta kappa energy");
    let kappa = read4(&f, "kappa");
    let energy = read4(&f, "energy");
    let n = read5(&f, "rotation_number");
    let err = read5(&f, "error_estimate");
    let status = f
        .dataset("status")
        .unwrap()
        .read::<u8, ndarray::Ix5>()
        .unwrap();
    let lambdas = f.dataset("lambda").unwrap().read_raw::<f64>().unwrap();
    let ss = f.dataset("s").unwrap().read_raw::<f64>().unwrap();
    let options = CellOptions {
        drift: false,
        ..CellOptions::default()
    };
    for (ib, beta) in [0.5, 3.0].into_iter().enumerate() {
        let body = EllipsoidBody::ellipsoid(0.5, beta, 0.5, 0.5).unwrap();
        for (il, &lambda) in lambdas.iter().enumerate() {
            // s = 0: ε = ∞, the high-energy limit N∞(λ), with its own status.
            assert!(kappa[[0, ib, il, 0]].is_infinite() && energy[[0, ib, il, 0]].is_infinite());
            let limit = high_energy_rotation_number(&body, lambda, 1e-10).unwrap();
            // At κ = λ√ε → ∞ V is one well round π/2, on the side U descends to: σ_sπ's.
            let top = slot(&f, rubber_atlas::family::Family::WellPi);
            assert_eq!(n[[0, ib, il, 0, top]], limit.value);
            assert_eq!(err[[0, ib, il, 0, top]], limit.error);
            assert_eq!(status[[0, ib, il, 0, top]], 4, "high_energy_limit");
            for (is, &s) in ss.iter().enumerate().skip(1) {
                let (k, e) = (lambda / s, 1.0 / (s * s));
                assert_eq!((kappa[[0, ib, il, is]], energy[[0, ib, il, is]]), (k, e));
                match solve_cell(&body, k, e, &options) {
                    Ok(c) if !c.components.is_empty() => {
                        for comp in &c.components {
                            let k = slot(&f, comp.family);
                            assert_eq!(
                                n[[0, ib, il, is, k]].to_bits(),
                                comp.rotation_number.to_bits()
                            );
                        }
                    }
                    _ => assert!(n
                        .slice(ndarray::s![0, ib, il, is, ..])
                        .iter()
                        .all(|x| x.is_nan())),
                }
            }
            // Along λ fixed, s → 0 converges to the limit (s = 0.1 is ε = 100).
            if lambda < 1.3 {
                assert!(
                    (n[[0, ib, il, 1, 0]] - limit.value).abs() < 0.05,
                    "β = {beta}, λ = {lambda}"
                );
            }
        }
    }
}

/// At κ = 0 the family layout keeps the mirror image leaning to θ > 0, the one continuous
/// with κ > 0 (for `well_pi` of α = 0.3, β = 0.6 it kept the one held at θ = 4.12 … 4.64,
/// i.e. leaning to θ < 0, and θ_min jumped to 1.649 at the next κ).
#[test]
fn the_family_layout_keeps_the_mirror_image_continuous_with_positive_kappa() {
    let dir = tempfile::tempdir().unwrap();
    let f = run_scene_text(
        dir.path(),
        "name = \"twins\"\n[body]\nnu = 0.5\neta = 0.5\n[axes]\nalpha = [0.3]\nbeta = [0.6]\n\
         kappa = { start = 0.0, stop = 0.04, num = 3 }\nenergy = [0.58]\n\
         [outputs]\nfields = [\"theta_min\", \"status\"]\n",
    );
    let theta_min = read5(&f, "theta_min");
    let row: Vec<f64> = (0..3).map(|k| theta_min[[0, 0, k, 0, 0]]).collect();
    assert!((row[0] - 1.6481).abs() < 1e-3, "{row:?}");
    assert!((row[1] - row[0]).abs() < 0.01, "{row:?}");
}
