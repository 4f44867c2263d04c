//! Families of tori (issue 20): a family is the same torus family over the whole plane, so
//! N of one family is continuous along κ- and ε-lines except across a critical curve, and a
//! family is born or dies only on one (where the number of tori changes); the cheap census
//! of the families agrees with the components the solver finds; and an atlas's component
//! axis has no slot that is empty in every cell.

use rubber_atlas::atlas::{self, variables, FLAG_FILL};
use rubber_atlas::cell::{solve_level, CellOptions, Status};
use rubber_atlas::critical::DiagramType;
use rubber_atlas::family::{Census, ComponentAxis, Family, Layout};
use rubber_atlas::scene::{Field, Scene};
use rubber_atlas::torus::EffectivePotential;
use rubber_atlas::{Body, EdgedShape, EllipsoidBody, Shape};
use std::collections::BTreeMap;

/// One body of each diagram type (paper §4, Fig. `bif`), the α = 0.3, β = 2, and a
/// mirror image (α < 0).
const BODIES: [(f64, f64); 7] = [
    (0.5, 3.0),
    (0.3, 2.0),
    (0.5, 0.5),
    (0.5, 1.1),
    (0.0, 0.6),
    (0.0, 2.0),
    (-0.5, 3.0),
];

fn body(alpha: f64, beta: f64) -> EllipsoidBody {
    EllipsoidBody::ellipsoid(alpha, beta, 0.5, 0.5).unwrap()
}

fn options() -> CellOptions {
    CellOptions {
        tol: 1e-10,
        drift: false,
        ..CellOptions::default()
    }
}

/// N of every family at each point of a line (None where the family does not exist or its
/// value is not a plain one: a separatrix, a tolerance not reached), and N of the first
/// component in θ_min order (the old layout's slot 0).
struct Line {
    by_family: BTreeMap<Family, Vec<Option<f64>>>,
    first_slot: Vec<Option<f64>>,
    /// The number of tori at each point (0 without motion).
    count: Vec<usize>,
    /// The families at each point.
    families: Vec<Vec<Family>>,
}

fn line<S: Shape>(b: &Body<S>, points: &[(f64, f64)]) -> Line {
    let mut by_family: BTreeMap<Family, Vec<Option<f64>>> = BTreeMap::new();
    let mut first_slot = Vec::new();
    let (mut count, mut families) = (Vec::new(), Vec::new());
    for (i, &(kappa, energy)) in points.iter().enumerate() {
        let potential = EffectivePotential::new(b, kappa);
        let cell = solve_level(&potential, energy, &options()).unwrap();
        count.push(cell.components.len());
        families.push(cell.components.iter().map(|c| c.family).collect());
        let plain = |s: Status| matches!(s, Status::Ok | Status::FixedPoint);
        first_slot.push(
            cell.components
                .first()
                .filter(|c| plain(c.status))
                .map(|c| c.rotation_number),
        );
        let mut seen = Vec::new();
        for c in &cell.components {
            assert!(
                !seen.contains(&c.family),
                "two components of {} at kappa {kappa} energy {energy}",
                c.family
            );
            seen.push(c.family);
            let values = by_family
                .entry(c.family)
                .or_insert_with(|| vec![None; points.len()]);
            values[i] = plain(c.status).then_some(c.rotation_number);
        }
    }
    Line {
        by_family,
        first_slot,
        count,
        families,
    }
}

/// The steps of `values` that jump: |N_{i+1} − N_i| more than `factor` times both
/// neighbouring steps (plus a floor), among runs of four consecutive existing values with
/// one number of tori (a step next to a family's birth or death, next to a separatrix, or
/// across a critical curve — where the number of tori changes — is not judged).
fn jumps(values: &[Option<f64>], count: &[usize], factor: f64) -> Vec<(usize, f64, f64)> {
    let mut out = Vec::new();
    for i in 1..values.len().saturating_sub(2) {
        let (Some(a), Some(b), Some(c), Some(d)) =
            (values[i - 1], values[i], values[i + 1], values[i + 2])
        else {
            continue;
        };
        if count[i - 1..=i + 2].iter().any(|&k| k != count[i]) {
            continue;
        }
        let step = (c - b).abs();
        let around = (b - a).abs().max((d - c).abs());
        if step > factor * around + 1e-9 {
            out.push((i, b, c));
        }
    }
    out
}

/// The energies of a body's lines: spread over U's range at κ = 0 and above its top.
fn energies<S: Shape>(b: &Body<S>) -> Vec<f64> {
    let potential = EffectivePotential::new(b, 0.0);
    let values: Vec<f64> = potential
        .critical_points()
        .iter()
        .map(|p| p.value)
        .collect();
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    [0.2, 0.5, 0.8, 1.1, 1.6, 2.5]
        .iter()
        .map(|f| lo + f * (hi - lo + 0.5))
        .collect()
}

/// Checks N of each family of `b` along κ- and ε-lines ([`energies`], five κ): a family is
/// born or dies only where the number of tori changes, and its N does not jump. Returns the
/// number of values judged and adds the families met to `seen`.
fn check_lines<S: Shape>(
    b: &Body<S>,
    name: &str,
    seen: &mut std::collections::BTreeSet<Family>,
) -> usize {
    const POINTS: usize = 240;
    let mut judged = 0;
    let mut lines: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for e in energies(b) {
        let points = (0..POINTS)
            .map(|i| (0.005 + 2.5 * i as f64 / (POINTS - 1) as f64, e))
            .collect();
        lines.push((format!("energy {e}"), points));
    }
    for kappa in [0.02, 0.2, 0.6, 1.0, 1.6] {
        let bottom = EffectivePotential::new(b, kappa).lowest_minimum().unwrap();
        let points = (0..POINTS)
            .map(|i| (kappa, bottom + 1e-6 + 5.0 * i as f64 / (POINTS - 1) as f64))
            .collect();
        lines.push((format!("kappa {kappa}"), points));
    }
    for (line_name, points) in &lines {
        let l = line(b, points);
        // A family is born or dies only where the number of tori changes.
        for i in 0..points.len() - 1 {
            assert!(
                l.families[i] == l.families[i + 1] || l.count[i] != l.count[i + 1],
                "{name}, {line_name}: {:?} at {:?} becomes {:?} at {:?} with {} tori on both \
                 sides",
                l.families[i],
                points[i],
                l.families[i + 1],
                points[i + 1],
                l.count[i]
            );
        }
        for (family, values) in &l.by_family {
            seen.insert(*family);
            judged += values.iter().flatten().count();
            let found = jumps(values, &l.count, 6.0);
            assert!(
                found.is_empty(),
                "{name}, {line_name}: N of {family} jumps at {:?}",
                found
                    .iter()
                    .map(|&(i, a, c)| (points[i], a, c))
                    .collect::<Vec<_>>()
            );
        }
    }
    judged
}

#[test]
fn n_of_each_family_is_continuous_along_kappa_and_energy_lines() {
    let mut judged = 0;
    let mut families_seen = std::collections::BTreeSet::new();
    for (alpha, beta) in BODIES {
        let name = format!(
            "alpha {alpha} beta {beta} ({:?})",
            DiagramType::of(alpha, beta)
        );
        judged += check_lines(&body(alpha, beta), &name, &mut families_seen);
    }
    // Every family of a κ ≠ 0 level was on some line, with thousands of values judged.
    for f in [Family::Well0, Family::WellPi, Family::WellEquator] {
        assert!(families_seen.contains(&f), "{f} never seen");
    }
    assert!(judged > 12_000, "{judged}");
}

/// The same for the edged bodies (docs/bodies.md): N of a family stays continuous where a
/// torus starts to cross a kink, and the symmetric wheel has its equator family.
#[test]
fn n_of_each_family_of_an_edged_body_is_continuous_along_lines() {
    let mut judged = 0;
    let mut families_seen = std::collections::BTreeSet::new();
    for (shape, nu, eta) in [
        (EdgedShape::disk(0.3).unwrap(), 2.0, 4.0),
        (EdgedShape::truncated_ball(0.2, 0.4).unwrap(), 0.7, 1.3),
        (EdgedShape::truncated_ball(-0.3, -0.5).unwrap(), 0.7, 1.3),
        (EdgedShape::wheel(0.25, 0.7).unwrap(), 0.7, 1.3),
        (EdgedShape::wheel(0.0, 0.5).unwrap(), 1.0, 2.0),
    ] {
        let name = format!("{shape:?}");
        let b = Body::new(shape, nu, eta).unwrap();
        judged += check_lines(&b, &name, &mut families_seen);
    }
    for f in [Family::Well0, Family::WellPi, Family::WellEquator] {
        assert!(families_seen.contains(&f), "{f} never seen");
    }
    assert!(judged > 8_000, "{judged}");
}

#[test]
fn the_theta_min_slot_jumps_where_the_family_does_not() {
    // The example: the demo body along κ at ε = 2.5. Slot 0 of the θ_min layout is
    // the well round θ = 0 while it exists and the well round θ = π after: N jumps from
    // about +0.69 to −0.78; each family's N does not. (The check above can fail.)
    let b = body(0.5, 3.0);
    let points: Vec<(f64, f64)> = (0..200)
        .map(|i| (0.1 + 1.9 * i as f64 / 199.0, 2.5))
        .collect();
    let l = line(&b, &points);
    let slot = jumps(&l.first_slot, &vec![0; l.count.len()], 6.0);
    assert_eq!(slot.len(), 1, "{slot:?}");
    let (_, before, after) = slot[0];
    assert!(before > 0.6 && after < -0.7, "{before} {after}");
    for values in l.by_family.values() {
        assert!(jumps(values, &l.count, 6.0).is_empty());
    }
    assert_eq!(
        l.by_family.keys().copied().collect::<Vec<_>>(),
        vec![Family::Well0, Family::WellPi]
    );
}

#[test]
fn families_are_named_after_the_wells_of_the_paper() {
    let family_at = |alpha: f64, beta: f64, kappa: f64, energy: f64| -> Vec<Family> {
        let b = body(alpha, beta);
        let potential = EffectivePotential::new(&b, kappa);
        potential
            .components(energy)
            .unwrap()
            .iter()
            .map(|c| c.family)
            .collect()
    };
    use Family::*;
    // Type (c), α = 0.5, β = 3: below the cusp two wells; above the saddle one torus round
    // both, of the family of σ_sπ, which it continues beyond the cusp κ_c; at κ = 0 the
    // equilibria σ0 and σπ, and rolling over the top above ε_min.
    assert_eq!(family_at(0.5, 3.0, 0.3, 2.5), vec![Well0, WellPi]);
    assert_eq!(family_at(0.5, 3.0, 0.3, 3.1), vec![WellPi]);
    assert_eq!(family_at(0.5, 3.0, 1.0, 3.1), vec![WellPi]);
    assert_eq!(family_at(0.5, 3.0, 1.0, 4.4), vec![WellPi]);
    assert_eq!(family_at(0.5, 3.0, 0.0, 2.5), vec![Well0, WellPi]);
    assert_eq!(family_at(0.5, 3.0, 0.0, 3.1), vec![OverTheTop]);
    // The mirror image α < 0 swaps the wells.
    assert_eq!(family_at(-0.5, 3.0, 0.3, 2.5), vec![Well0, WellPi]);
    assert_eq!(family_at(-0.5, 3.0, 1.0, 3.1), vec![Well0]);
    // Type (a): the inclined equilibrium θ* in (π/2, π) and its mirror −θ* at κ = 0: two
    // components of one family (the body leaning either way); the well of σ_sπ for κ > 0.
    assert_eq!(family_at(0.5, 0.5, 0.0, 0.45), vec![WellPi, WellPi]);
    assert_eq!(family_at(0.5, 0.5, 0.0, 0.6), vec![WellPi]);
    assert_eq!(family_at(0.5, 0.5, 0.5, 1.2), vec![WellPi]);
    // α = 0: type (d) rolls on the equator; type (e) has two symmetric wells below κ_c
    // (= √((β² − 1)/β) = 1.2247 at β = 2) and the equator above it.
    assert_eq!(family_at(0.0, 0.6, 0.5, 1.0), vec![WellEquator]);
    assert_eq!(
        family_at(0.0, 0.6, 0.0, 0.8),
        vec![WellEquator, WellEquator]
    );
    assert_eq!(family_at(0.0, 2.0, 0.5, 1.8), vec![Well0, WellPi]);
    assert_eq!(family_at(0.0, 2.0, 0.5, 2.3), vec![WellEquator]);
    assert_eq!(family_at(0.0, 2.0, 1.5, 4.0), vec![WellEquator]);
}

#[test]
fn the_census_agrees_with_the_components_over_the_whole_domain() {
    // Seeded pseudo-random cells over the whole domain: α in (−1, 1), β from 1e-2 to 1e2
    // (log), κ from 0 (a tenth of the cells exactly 0) to 1e9, ε from the bottom of V up.
    // At large κ the well sits within |α|/κ² of π/2, where rounding once put it on the
    // wrong side (α < 0 labelled well_pi at κ ≈ 1e8): the mirror body −α must have the
    // mirror families at every cell.
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut checked = 0;
    for _ in 0..3000 {
        let alpha = 1.98 * uniform() - 0.99;
        let beta = 10f64.powf(4.0 * uniform() - 2.0);
        let kappa = if uniform() < 0.1 {
            0.0
        } else {
            10f64.powf(12.0 * uniform() - 3.0)
        };
        let b = body(alpha, beta);
        let potential = EffectivePotential::new(&b, kappa);
        let bottom = potential.lowest_minimum().unwrap();
        let energy = bottom + 10f64.powf(6.0 * uniform() - 5.0) * (1.0 + bottom.abs());
        let census = potential.families(energy).unwrap();
        let solved: Vec<Family> = potential
            .components(energy)
            .unwrap()
            .iter()
            .map(|c| c.family)
            .collect();
        assert_eq!(
            census, solved,
            "alpha {alpha} beta {beta} kappa {kappa} energy {energy}"
        );
        // Every family is one the census may expect of the body (its early end is safe).
        let possible = rubber_atlas::family::possible_for_ellipsoid(alpha, beta, kappa == 0.0);
        for f in &solved {
            assert!(
                possible[usize::from(f.code())],
                "{f} at alpha {alpha} beta {beta} kappa {kappa} energy {energy}"
            );
        }
        let mirror = body(-alpha, beta);
        let mirrored: Vec<Family> = EffectivePotential::new(&mirror, kappa)
            .families(energy)
            .unwrap()
            .iter()
            .rev()
            .map(|f| match f {
                Family::Well0 => Family::WellPi,
                Family::WellPi => Family::Well0,
                other => *other,
            })
            .collect();
        if kappa != 0.0 {
            assert_eq!(
                solved, mirrored,
                "mirror of alpha {alpha} beta {beta} kappa {kappa} energy {energy}"
            );
        }
        // Two components of one family only at κ = 0 (mirror images).
        if kappa != 0.0 {
            let mut unique = solved.clone();
            unique.dedup();
            assert_eq!(
                unique.len(),
                solved.len(),
                "{alpha} {beta} {kappa} {energy}"
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 3000);
}

#[test]
fn the_families_a_body_can_have_hold_at_the_type_boundaries_and_small_kappa() {
    // Bodies on either side of β² = 1 + |α| (where the second well is born, at κ = 0) and
    // α = ±0, swept over small κ and the energies of their wells and saddles.
    let mut checked = 0;
    for alpha in [0.5, -0.5, 1e-12, -1e-12, 0.0, 0.3] {
        for factor in [1.0 - 1e-3, 1.0 - 1e-9, 1.0, 1.0 + 1e-9, 1.0 + 1e-3] {
            let beta = ((1.0 + f64::abs(alpha)) * factor).sqrt();
            let b = body(alpha, beta);
            let possible = rubber_atlas::family::possible_for_ellipsoid(alpha, beta, false);
            for kappa in [1e-8, 1e-5, 1e-3, 0.05, 0.5, 2.0] {
                let potential = EffectivePotential::new(&b, kappa);
                let mut levels: Vec<f64> = potential
                    .critical_points()
                    .iter()
                    .flat_map(|p| [p.value * (1.0 + 1e-12), p.value + 1e-6, p.value + 0.3])
                    .collect();
                levels.push(potential.lowest_minimum().unwrap() + 5.0);
                for energy in levels {
                    for f in potential.families(energy).unwrap_or_default() {
                        assert!(
                            possible[usize::from(f.code())],
                            "{f} at alpha {alpha} beta {beta} kappa {kappa} energy {energy}"
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 300, "{checked}");
}

#[test]
fn an_atlas_has_no_slot_empty_everywhere_and_each_slot_is_one_family() {
    for layout in ["family", "theta_min"] {
        let text = format!(
            "name = \"t\"\n[body]\nnu = 0.5\neta = 0.5\n[axes]\nalpha = [0.3, 0.5]\n\
             beta = [2.0, 3.0]\nkappa = {{ start = 0.0, stop = 2.0, num = 41 }}\n\
             energy = {{ start = 0.5, stop = 4.5, num = 41 }}\n[outputs]\nlayout = \"{layout}\"\n"
        );
        let scene = Scene::parse(&text, "t.toml").unwrap();
        let axis = atlas::component_axis(&scene, &|| false);
        assert_eq!(axis.layout, Layout::from_name(layout).unwrap());
        let vars = variables(&[Field::RotationNumber, Field::Status]);
        let family_index = vars.iter().position(|v| v.name == "family").unwrap();
        let slots = axis.len();
        let mut used = vec![false; slots];
        let mut census = Census::default();
        for ia in 0..2 {
            for ib in 0..2 {
                let rows: Vec<usize> = (0..41).collect();
                let block = atlas::compute_rows(
                    &scene,
                    &vars,
                    &axis,
                    ia,
                    ib..ib + 1,
                    &rows,
                    &|_| {},
                    &|| false,
                )
                .unwrap();
                let atlas::Column::U8(family) = &block.columns[family_index] else {
                    panic!("family is u8");
                };
                for (i, &f) in family.iter().enumerate() {
                    if f == FLAG_FILL {
                        continue;
                    }
                    used[i % slots] = true;
                    if axis.layout == Layout::Family {
                        assert_eq!(f, axis.labels[i % slots]);
                    }
                    census.add(&[Family::from_code(f).unwrap()]);
                }
                let status = block.flags(&vars, "cell_status").unwrap();
                assert!(status.iter().all(|&s| s != atlas::cell_status::FAILED));
            }
        }
        assert!(
            used.iter().all(|&u| u),
            "{layout}: {used:?} {:?}",
            axis.labels
        );
        if axis.layout == Layout::Family {
            // Type (c) bodies with κ = 0: both wells and over the top.
            assert_eq!(axis.labels, vec![0, 1, 3]);
            assert_eq!(ComponentAxis::of(Layout::Family, &census), axis);
        } else {
            assert_eq!(axis.labels, vec![0, 1]);
        }
    }
}
