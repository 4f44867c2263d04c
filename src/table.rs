//! Tables along one dimension: a trajectory over time `t`, the sampled fixed-point curves of
//! a bifurcation diagram and the points of resonance curves over `sample`. Every column
//! carries its CF metadata here, once: the store writes a table to HDF5 or CSV, and the
//! Python package turns the same table into an xarray Dataset.

use crate::cf::{self, AttrValue, Units};
use crate::critical::CriticalSet;
use crate::family::Family;
use crate::resonance::Curve;
use crate::trajectory::Trajectory;

/// The values of one column.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    F64(Vec<f64>),
    /// Indices (of a curve, a segment, a point or a component).
    I32(Vec<i32>),
    /// Flags, with `flag_values` and `flag_meanings`.
    U8(Vec<u8>),
}

impl Values {
    pub fn len(&self) -> usize {
        match self {
            Values::F64(v) => v.len(),
            Values::I32(v) => v.len(),
            Values::U8(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One column of a table with its CF attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct TableColumn {
    pub name: &'static str,
    pub values: Values,
    pub long_name: &'static str,
    pub units: Units,
    /// `flag_values` and `flag_meanings` of a flag column.
    pub flags: Option<(&'static [u8], &'static str)>,
}

/// A table: equal-length columns along one dimension, whose coordinate is the first column
/// (named as the dimension), and root attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub dimension: &'static str,
    pub columns: Vec<TableColumn>,
    pub attributes: Vec<(String, AttrValue)>,
}

impl Table {
    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |c| c.values.len())
    }
}

fn column(
    name: &'static str,
    values: Values,
    long_name: &'static str,
    units: Units,
) -> TableColumn {
    TableColumn {
        name,
        values,
        long_name,
        units,
        flags: None,
    }
}

fn flag_column(
    name: &'static str,
    values: Vec<u8>,
    long_name: &'static str,
    flags: (&'static [u8], &'static str),
) -> TableColumn {
    TableColumn {
        name,
        values: Values::U8(values),
        long_name,
        units: cf::NUMBER,
        flags: Some(flags),
    }
}

/// The attributes of a new table: its CF `title`.
fn title(text: &str) -> Vec<(String, AttrValue)> {
    vec![("title".into(), AttrValue::Text(text.into()))]
}

/// The `sample` coordinate 0, 1, …, n − 1 of a table of curve points.
fn sample_column(n: usize) -> TableColumn {
    column(
        "sample",
        Values::I32((0..n as i32).collect()),
        "index of the sample",
        cf::NUMBER,
    )
}

/// The trajectory's samples along `t` (the paper's Figs. `res`, `xy`).
pub fn trajectory(traj: &Trajectory) -> Table {
    let f = |v: &Vec<f64>| Values::F64(v.clone());
    let columns = vec![
        column("t", f(&traj.t), "time", cf::TIME),
        column(
            "theta",
            f(&traj.theta),
            "inclination of the symmetry axis to the vertical",
            cf::ANGLE,
        ),
        column(
            "theta_dot",
            f(&traj.theta_dot),
            "rate of inclination",
            cf::RATE,
        ),
        column("phi", f(&traj.phi), "proper rotation angle", cf::ANGLE),
        column(
            "psi",
            f(&traj.psi),
            "precession angle (azimuth of the axis)",
            cf::ANGLE,
        ),
        column("x_c", f(&traj.x_c), "x of the centre of mass", cf::LENGTH),
        column("y_c", f(&traj.y_c), "y of the centre of mass", cf::LENGTH),
        column(
            "z_c",
            f(&traj.z_c),
            "height of the centre of mass",
            cf::LENGTH,
        ),
        column("x_p", f(&traj.x_p), "x of the contact point", cf::LENGTH),
        column("y_p", f(&traj.y_p), "y of the contact point", cf::LENGTH),
    ];
    Table {
        dimension: "t",
        columns,
        attributes: title("rubber-atlas trajectory"),
    }
}

/// The branch codes of a diagram table, in the order of `flag_values` 0, 1, 2, 3.
pub const BRANCH_NAMES: [&str; 4] = ["sigma_s0", "sigma_u", "sigma_spi", "sigma_pi2"];

/// The sampled fixed-point curves of a critical set (paper §4, Fig. `bif`), one row per
/// point; the set's summary goes in the attributes as JSON (`critical_set_json`).
pub fn diagram(set: &CriticalSet) -> Table {
    diagram_until(set, &|| false).expect("never stopped")
}

/// [`diagram`], given up (None) when `stop` says so, asked before each column (a column of
/// 5e7 samples takes some 0.4 s to gather: the whole table 4 s, which Ctrl-C waited for).
pub fn diagram_until(set: &CriticalSet, stop: &dyn Fn() -> bool) -> Option<Table> {
    let points: Vec<(usize, u8, &crate::critical::FixedPoint)> = set
        .branches
        .iter()
        .enumerate()
        .flat_map(|(i, b)| {
            let code = BRANCH_NAMES.iter().position(|n| *n == b.name).unwrap_or(0) as u8;
            b.points.iter().map(move |p| (i, code, p))
        })
        .collect();
    let f = |g: &dyn Fn(&crate::critical::FixedPoint) -> f64| {
        Values::F64(points.iter().map(|(_, _, p)| g(p)).collect())
    };
    // Each column gathered in turn, `stop` asked before each.
    let makers: [&dyn Fn() -> TableColumn; 10] = [
        &|| sample_column(points.len()),
        &|| {
            column(
                "segment",
                Values::I32(points.iter().map(|(i, _, _)| *i as i32).collect()),
                "index of the run of one stability along a branch",
                cf::NUMBER,
            )
        },
        &|| {
            flag_column(
                "branch",
                points.iter().map(|(_, c, _)| *c).collect(),
                "branch of permanent rotations",
                (&[0, 1, 2, 3], "sigma_s0 sigma_u sigma_spi sigma_pi2"),
            )
        },
        &|| {
            column(
                "theta0",
                f(&|p| p.theta0),
                "inclination of the permanent rotation",
                cf::ANGLE,
            )
        },
        &|| {
            column(
                "kappa",
                f(&|p| p.kappa),
                "integral F2 on the curve (kappa >= 0)",
                cf::PAPER,
            )
        },
        &|| {
            column(
                "energy",
                f(&|p| p.energy),
                "energy on the curve",
                cf::ENERGY,
            )
        },
        &|| {
            flag_column(
                "stable",
                points.iter().map(|(_, _, p)| u8::from(p.stable)).collect(),
                "linear stability of the permanent rotation",
                (&[0, 1], "unstable stable"),
            )
        },
        &|| {
            column(
                "rho_c",
                f(&|p| p.rho_c),
                "radius of the circle of the centre of mass",
                cf::LENGTH,
            )
        },
        &|| {
            column(
                "rho_p",
                f(&|p| p.rho_p),
                "radius of the circle of the contact point",
                cf::LENGTH,
            )
        },
        &|| {
            column(
                "rotation_number",
                f(&|p| p.rotation_number.unwrap_or(f64::NAN)),
                "rotation number of the small oscillations, -psi_dot/omega0 (NaN where unstable)",
                cf::NUMBER,
            )
        },
    ];
    let mut columns = Vec::with_capacity(makers.len());
    for make in makers {
        if stop() {
            return None;
        }
        columns.push(make());
    }
    Some(Table {
        dimension: "sample",
        columns,
        attributes: title("rubber-atlas critical set: the fixed-point curves"),
    })
}

/// The points of traced resonance curves N = p/q, one row per point, curve after curve.
pub fn resonance(curves: &[Curve]) -> Table {
    let rows: Vec<(usize, usize, &crate::resonance::CurvePoint)> = curves
        .iter()
        .enumerate()
        .flat_map(|(i, c)| c.points.iter().enumerate().map(move |(j, p)| (i, j, p)))
        .collect();
    let f = |g: &dyn Fn(&crate::resonance::CurvePoint) -> f64| {
        Values::F64(rows.iter().map(|(_, _, p)| g(p)).collect())
    };
    let index = |g: &dyn Fn(&(usize, usize, &crate::resonance::CurvePoint)) -> usize| {
        Values::I32(rows.iter().map(|r| g(r) as i32).collect())
    };
    let columns = vec![
        sample_column(rows.len()),
        column("curve", index(&|r| r.0), "index of the curve", cf::NUMBER),
        column(
            "point",
            index(&|r| r.1),
            "index of the point along its curve",
            cf::NUMBER,
        ),
        column("kappa", f(&|p| p.kappa), "kappa = F2", cf::PAPER),
        column("energy", f(&|p| p.energy), "energy", cf::ENERGY),
        column(
            "rotation_number",
            f(&|p| p.rotation_number),
            "rotation number N",
            cf::NUMBER,
        ),
        column(
            "error_estimate",
            f(&|p| p.error_estimate),
            "estimated absolute error of rotation_number",
            cf::NUMBER,
        ),
        column(
            "component",
            index(&|r| r.2.component),
            "component of the cell, in increasing theta_min",
            cf::NUMBER,
        ),
        flag_column(
            "family",
            rows.iter().map(|r| r.2.family.code()).collect(),
            "torus family",
            (&Family::VALUES, Family::MEANINGS),
        ),
        column(
            "theta_min",
            f(&|p| p.theta_min),
            "lower turning point of theta",
            cf::ANGLE,
        ),
        column(
            "theta_max",
            f(&|p| p.theta_max),
            "upper turning point of theta",
            cf::ANGLE,
        ),
        column(
            "well",
            f(&|p| p.well),
            "theta of the minimum of V inside the component",
            cf::ANGLE,
        ),
        flag_column(
            "closed",
            rows.iter().map(|r| u8::from(curves[r.0].closed)).collect(),
            "whether the point's curve closes on itself",
            (&[0, 1], "open closed"),
        ),
    ];
    Table {
        dimension: "sample",
        columns,
        attributes: title("rubber-atlas resonance curves"),
    }
}
