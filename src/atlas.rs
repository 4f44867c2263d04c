//! The grid driver: splits a scene's grid into work units (blocks of κ-rows of one (α, β)
//! slice), computes them with rayon one κ-row at a time, and lays the results out as the
//! dense per-cell and per-component arrays of the atlas file (SPEC §3.2).

#[cfg(test)]
use crate::cell::CellOptions;
use crate::cell::{solve_high_energy_limit, solve_level, CellResult, ComponentResult, Status};
use crate::error::{AtlasError, Result};
use crate::scene::{Field, Plane, Scene};
use crate::torus::{EffectivePotential, MotionKind};
use rayon::prelude::*;
use std::ops::Range;

/// Component slots per cell. {V ≤ ε} has one component per well of V, and V has at most two
/// minima for an ellipsoid of revolution (paper §4: σ_s0 and σ_sπ of type (c); θ* and its
/// mirror at κ = 0); the third slot is a margin. A cell with more components is marked
/// `failed` and keeps its first three.
pub const COMPONENT_SLOTS: usize = 3;

/// Cells per work unit, about: the unit of resume and of sharding.
const UNIT_CELLS: usize = 4096;

/// A cell's status (`cell_status`): motion, no motion, the solver failed on it, or it was
/// never computed in this file (a shard's cells of other shards: the file's fill value).
pub mod cell_status {
    pub const OK: u8 = 0;
    pub const NO_MOTION: u8 = 1;
    pub const FAILED: u8 = 2;
    pub const NOT_COMPUTED: u8 = 3;
    pub const VALUES: [u8; 4] = [OK, NO_MOTION, FAILED, NOT_COMPUTED];
    pub const MEANINGS: &str = "ok no_motion failed not_computed";
}

/// A component's status flag (`status`).
pub mod status_flag {
    pub const OK: u8 = 0;
    pub const TOLERANCE_NOT_REACHED: u8 = 1;
    pub const FIXED_POINT: u8 = 2;
    pub const SEPARATRIX: u8 = 3;
    pub const HIGH_ENERGY_LIMIT: u8 = 4;
    pub const VALUES: [u8; 5] = [
        OK,
        TOLERANCE_NOT_REACHED,
        FIXED_POINT,
        SEPARATRIX,
        HIGH_ENERGY_LIMIT,
    ];
    pub const MEANINGS: &str = "ok tolerance_not_reached fixed_point separatrix high_energy_limit";
}

/// A component's motion flag (`motion`).
pub mod motion_flag {
    pub const LIBRATION: u8 = 0;
    pub const FIXED_POINT: u8 = 1;
    pub const ROTATION: u8 = 2;
    pub const VALUES: [u8; 3] = [LIBRATION, FIXED_POINT, ROTATION];
    pub const MEANINGS: &str = "libration fixed_point rotation";
}

/// The fill value of the u8 variables where a component does not exist.
pub const FLAG_FILL: u8 = 255;

/// How a variable is laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// One u8 per cell: dims (alpha, beta, kappa, energy).
    CellFlag,
    /// One f64 per cell and component slot: dims (alpha, beta, kappa, energy, component).
    Value,
    /// One u8 per cell and component slot.
    Flag,
    /// One f64 per cell: κ or ε of the cell when they are not axes (CF auxiliary
    /// coordinates).
    CellValue,
}

impl Kind {
    /// One value per cell (no component dimension).
    pub fn per_cell(self) -> bool {
        matches!(self, Kind::CellFlag | Kind::CellValue)
    }

    /// Bytes per cell of a variable of this kind, uncompressed.
    pub fn bytes_per_cell(self) -> usize {
        let value = match self {
            Kind::Value | Kind::CellValue => 8,
            Kind::Flag | Kind::CellFlag => 1,
        };
        if self.per_cell() {
            value
        } else {
            value * COMPONENT_SLOTS
        }
    }
}

/// One variable of the atlas file.
#[derive(Debug, Clone)]
pub struct Variable {
    pub name: &'static str,
    pub kind: Kind,
    pub long_name: &'static str,
    pub units: &'static str,
    /// `flag_values` and `flag_meanings` for flag variables.
    pub flags: Option<(&'static [u8], &'static str)>,
    value: fn(&ComponentResult) -> f64,
}

const TIME: &str = "sqrt(b3/g)";
const RATE: &str = "rad/sqrt(b3/g)";

fn float(
    name: &'static str,
    long_name: &'static str,
    units: &'static str,
    value: fn(&ComponentResult) -> f64,
) -> Variable {
    Variable {
        name,
        kind: Kind::Value,
        long_name,
        units,
        flags: None,
        value,
    }
}

fn flag(
    name: &'static str,
    long_name: &'static str,
    flags: (&'static [u8], &'static str),
    value: fn(&ComponentResult) -> f64,
) -> Variable {
    Variable {
        name,
        kind: Kind::Flag,
        long_name,
        units: "1",
        flags: Some(flags),
        value,
    }
}

/// The variables of a scene's file: its fields' ([`variables`]) and, where κ or ε is not an
/// axis of the plane, that value per cell (a CF auxiliary coordinate).
pub fn scene_variables(scene: &Scene) -> Vec<Variable> {
    let mut vars = variables(&scene.fields);
    for &name in scene.plane.auxiliary() {
        vars.push(Variable {
            name,
            kind: Kind::CellValue,
            long_name: if name == "kappa" {
                "kappa = F2, the first integral of the reduction, of each cell"
            } else {
                "energy, the value of the reduced energy integral, of each cell"
            },
            units: "paper units (m = b3 = g = 1)",
            flags: None,
            value: |_| f64::NAN,
        });
    }
    vars
}

/// The variables written for `fields`, in file order: `n_components` and `cell_status`
/// always; each requested field, and for the floating-point quantities their estimated
/// absolute error (`<name>_error`; N's is `error_estimate`).
pub fn variables(fields: &[Field]) -> Vec<Variable> {
    let mut vars = vec![
        Variable {
            name: "n_components",
            kind: Kind::CellFlag,
            long_name: "number of connected components of the allowed set {V <= energy}",
            units: "1",
            flags: None,
            value: |_| 0.0,
        },
        Variable {
            name: "cell_status",
            kind: Kind::CellFlag,
            long_name: "status of the cell",
            units: "1",
            flags: Some((&cell_status::VALUES, cell_status::MEANINGS)),
            value: |_| 0.0,
        },
    ];
    for &field in fields {
        let (var, error): (Variable, Option<Variable>) = match field {
            Field::ThetaMin => (
                float("theta_min", "lower turning point of theta", "rad", |c| {
                    c.theta_min
                }),
                None,
            ),
            Field::ThetaMax => (
                float("theta_max", "upper turning point of theta", "rad", |c| {
                    c.theta_max
                }),
                None,
            ),
            Field::Period => (
                float("period", "period T of theta", TIME, |c| c.period),
                Some(float(
                    "period_error",
                    "estimated absolute error of period",
                    TIME,
                    |c| c.errors.period,
                )),
            ),
            Field::OmegaTheta => (
                float("omega_theta", "frequency of theta, 2 pi / T", RATE, |c| {
                    c.omega_theta
                }),
                Some(float(
                    "omega_theta_error",
                    "estimated absolute error of omega_theta",
                    RATE,
                    |c| c.errors.omega_theta,
                )),
            ),
            Field::OmegaPsi => (
                float(
                    "omega_psi",
                    "mean precession rate, (psi advance over a period) / T",
                    RATE,
                    |c| c.omega_psi,
                ),
                Some(float(
                    "omega_psi_error",
                    "estimated absolute error of omega_psi",
                    RATE,
                    |c| c.errors.omega_psi,
                )),
            ),
            Field::RotationNumber => (
                float(
                    "rotation_number",
                    "rotation number N = -omega_psi / omega_theta",
                    "1",
                    |c| c.rotation_number,
                ),
                None,
            ),
            Field::Drift => (
                float(
                    "drift",
                    "displacement |delta zeta| of the centre of mass over one period of theta",
                    "b3",
                    |c| c.drift,
                ),
                Some(float(
                    "drift_error",
                    "estimated absolute error of drift",
                    "b3",
                    |c| c.errors.drift,
                )),
            ),
            Field::DriftRadius => (
                float(
                    "drift_radius",
                    "radius |delta zeta| / (2 |sin pi N|) of the circle of stroboscopic points",
                    "b3",
                    |c| c.drift_radius,
                ),
                Some(float(
                    "drift_radius_error",
                    "estimated absolute error of drift_radius",
                    "b3",
                    |c| c.errors.drift_radius,
                )),
            ),
            Field::Bounded => (
                flag(
                    "bounded",
                    "whether the path of the body on the plane stays bounded",
                    (&[0, 1], "unbounded bounded"),
                    |c| match c.bounded {
                        Some(true) => 1.0,
                        Some(false) => 0.0,
                        None => f64::NAN,
                    },
                ),
                None,
            ),
            Field::Motion => (
                flag(
                    "motion",
                    "kind of motion of the component",
                    (&motion_flag::VALUES, motion_flag::MEANINGS),
                    |c| {
                        f64::from(match c.motion {
                            MotionKind::Libration => motion_flag::LIBRATION,
                            MotionKind::FixedPoint => motion_flag::FIXED_POINT,
                            MotionKind::Rotation => motion_flag::ROTATION,
                        })
                    },
                ),
                None,
            ),
            Field::Status => (
                flag(
                    "status",
                    "how to read the component's values",
                    (&status_flag::VALUES, status_flag::MEANINGS),
                    |c| {
                        f64::from(match c.status {
                            Status::Ok | Status::NoMotion => status_flag::OK,
                            Status::ToleranceNotReached => status_flag::TOLERANCE_NOT_REACHED,
                            Status::FixedPoint => status_flag::FIXED_POINT,
                            Status::Separatrix => status_flag::SEPARATRIX,
                            Status::HighEnergyLimit => status_flag::HIGH_ENERGY_LIMIT,
                        })
                    },
                ),
                None,
            ),
            Field::ErrorEstimate => (
                float(
                    "error_estimate",
                    "estimated absolute error of rotation_number",
                    "1",
                    |c| c.error_estimate,
                ),
                None,
            ),
        };
        vars.push(var);
        vars.extend(error);
    }
    vars
}

/// The data of one variable over a block of cells.
#[derive(Debug, Clone, PartialEq)]
pub enum Column {
    F64(Vec<f64>),
    U8(Vec<u8>),
}

impl Column {
    fn new(kind: Kind, len: usize) -> Column {
        match kind {
            Kind::Value => Column::F64(vec![f64::NAN; len * COMPONENT_SLOTS]),
            Kind::Flag => Column::U8(vec![FLAG_FILL; len * COMPONENT_SLOTS]),
            Kind::CellFlag => Column::U8(vec![0; len]),
            Kind::CellValue => Column::F64(vec![f64::NAN; len]),
        }
    }

    fn append(&mut self, other: Column) {
        match (self, other) {
            (Column::F64(a), Column::F64(b)) => a.extend(b),
            (Column::U8(a), Column::U8(b)) => a.extend(b),
            _ => unreachable!("columns of one variable have one type"),
        }
    }
}

/// The values of every variable over a block of cells in (κ, ε) row-major order, with the
/// component slot fastest for per-component variables.
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    pub cells: usize,
    pub columns: Vec<Column>,
}

impl Block {
    /// A block of `cells` cells with every value at its fill.
    pub fn empty(variables: &[Variable], cells: usize) -> Block {
        Block {
            cells,
            columns: variables
                .iter()
                .map(|v| Column::new(v.kind, cells))
                .collect(),
        }
    }

    /// The blocks one after the other (allocated once: growing by appends would leave the
    /// heap fragmented with slice-sized holes).
    pub fn concat(variables: &[Variable], blocks: Vec<Block>) -> Block {
        let cells: usize = blocks.iter().map(|b| b.cells).sum();
        let mut columns: Vec<Column> = variables
            .iter()
            .map(|v| {
                let n = if v.kind.per_cell() {
                    cells
                } else {
                    cells * COMPONENT_SLOTS
                };
                match v.kind {
                    Kind::Value | Kind::CellValue => Column::F64(Vec::with_capacity(n)),
                    Kind::Flag | Kind::CellFlag => Column::U8(Vec::with_capacity(n)),
                }
            })
            .collect();
        for b in blocks {
            for (a, c) in columns.iter_mut().zip(b.columns) {
                a.append(c);
            }
        }
        Block { cells, columns }
    }

    /// The u8 values of the variable `name`, if it is among `variables`.
    pub fn flags<'b>(&'b self, variables: &[Variable], name: &str) -> Option<&'b [u8]> {
        let i = variables.iter().position(|v| v.name == name)?;
        match &self.columns[i] {
            Column::U8(x) => Some(x),
            Column::F64(_) => None,
        }
    }
}

/// A work unit: rows `rows` of κ of the slice (α_{ia}, β_{ib}).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unit {
    /// Position in [`units`].
    pub index: usize,
    pub alpha_index: usize,
    pub beta_index: usize,
    pub rows: Range<usize>,
}

/// κ-rows per work unit: about [`UNIT_CELLS`] cells. A unit is also one chunk of the file.
pub fn rows_per_unit(shape: [usize; 4]) -> usize {
    let [_, _, nk, ne] = shape;
    UNIT_CELLS.div_ceil(ne.max(1)).clamp(1, nk.max(1))
}

/// The grid's work units, slice after slice (α slowest), each of about [`UNIT_CELLS`] cells
/// (whole κ-rows). The split depends on the grid alone, never on threads or shards.
pub fn units(shape: [usize; 4]) -> Vec<Unit> {
    let [na, nb, nk, _] = shape;
    let rows_per_unit = rows_per_unit(shape);
    let mut out = Vec::new();
    for ia in 0..na {
        for ib in 0..nb {
            for start in (0..nk).step_by(rows_per_unit) {
                out.push(Unit {
                    index: out.len(),
                    alpha_index: ia,
                    beta_index: ib,
                    rows: start..(start + rows_per_unit).min(nk),
                });
            }
        }
    }
    out
}

/// Shard `index` of `count` (1-based, as `--shard I/N`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole grid.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Parses `I/N` with 1 ≤ I ≤ N.
    pub fn parse(text: &str) -> Result<Shard> {
        let bad = |reason: &str| AtlasError::Atlas {
            path: format!("--shard {text}"),
            reason: reason.to_string(),
        };
        let (i, n) = text
            .split_once('/')
            .ok_or_else(|| bad("expected I/N, e.g. 2/8"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| bad("I is not a whole number"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| bad("N is not a whole number"))?;
        if count == 0 || index == 0 || index > count {
            return Err(bad("needs 1 <= I <= N"));
        }
        Ok(Shard { index, count })
    }

    /// The contiguous range of unit indices that belongs to this shard out of `total`.
    pub fn units(&self, total: usize) -> Range<usize> {
        // In 128 bits: total · index does not overflow for any usize shard.
        let at = |i: usize| (total as u128 * i as u128 / self.count as u128) as usize;
        at(self.index - 1)..at(self.index)
    }

    /// Checks that this shard of a grid of `total` work units has at least one unit.
    pub fn check_against(&self, total: usize) -> Result<()> {
        if self.index == 0 || self.index > self.count {
            return Err(AtlasError::Atlas {
                path: format!("shard {self}"),
                reason: "needs 1 <= I <= N".into(),
            });
        }
        if self.count > total {
            return Err(AtlasError::Atlas {
                path: format!("shard {self}"),
                reason: format!("the grid has only {total} work units: use at most {total} shards"),
            });
        }
        Ok(())
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Computes the κ-rows `rows` (in that order) of slice (ia, ib), rows shared out by rayon one
/// at a time (rows differ several-fold in cost); `progress` is called with the number of
/// cells after each row. Every cell is computed on its own, so the values do not depend on
/// the number of threads or on which rows are computed together.
pub fn compute_rows(
    scene: &Scene,
    variables: &[Variable],
    alpha_index: usize,
    beta_index: usize,
    rows: &[usize],
    progress: &(dyn Fn(usize) + Sync),
) -> Block {
    let body = scene.body(alpha_index, beta_index);
    let columns = &scene.energy.values;
    let options = &scene.options;
    let blocks: Vec<Block> = rows
        .par_iter()
        .with_max_len(1)
        .map(|&row| {
            let row_value = scene.kappa.values[row];
            let mut block = Block::empty(variables, columns.len());
            match scene.plane {
                Plane::KappaEnergy | Plane::KappaExcess => {
                    let potential = EffectivePotential::new(&body, row_value);
                    // The excess energy is measured from the bottom of V at this κ.
                    let base = match scene.plane {
                        Plane::KappaExcess => potential.lowest_minimum().unwrap_or(f64::NAN),
                        _ => 0.0,
                    };
                    for (j, &column) in columns.iter().enumerate() {
                        let energy = if scene.plane == Plane::KappaExcess {
                            base + column
                        } else {
                            column
                        };
                        fill_cell(&mut block, variables, j, (row_value, energy), || {
                            solve_level(&potential, energy, options)
                        });
                    }
                }
                Plane::Compact => {
                    // κ = λ/s, ε = 1/s²: every cell has its own κ; s = 0 is ε = ∞.
                    for (j, &s) in columns.iter().enumerate() {
                        if s == 0.0 {
                            fill_cell(
                                &mut block,
                                variables,
                                j,
                                (f64::INFINITY, f64::INFINITY),
                                || solve_high_energy_limit(&body, row_value, options),
                            );
                        } else {
                            let (kappa, energy) = (row_value / s, 1.0 / (s * s));
                            fill_cell(&mut block, variables, j, (kappa, energy), || {
                                solve_level(&EffectivePotential::new(&body, kappa), energy, options)
                            });
                        }
                    }
                }
            }
            progress(columns.len());
            block
        })
        .collect();
    Block::concat(variables, blocks)
}

/// One cell of `block`: `solve` gives its components; `(kappa, energy)` are its κ and ε,
/// written where they are auxiliary coordinates.
fn fill_cell(
    block: &mut Block,
    variables: &[Variable],
    cell: usize,
    (kappa, energy): (f64, f64),
    solve: impl FnOnce() -> Result<CellResult>,
) {
    // A panic in the solver is a bug, but one cell must not end a run of millions: it is
    // recorded as a failed cell.
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(solve));
    let (status, components) = match result {
        Ok(Ok(c)) if c.status == Status::NoMotion => (cell_status::NO_MOTION, Vec::new()),
        Ok(Ok(c)) if c.components.len() > COMPONENT_SLOTS => (cell_status::FAILED, c.components),
        Ok(Ok(c)) => (cell_status::OK, c.components),
        Ok(Err(_)) | Err(_) => (cell_status::FAILED, Vec::new()),
    };
    for (var, column) in variables.iter().zip(block.columns.iter_mut()) {
        match (var.kind, column) {
            (Kind::CellFlag, Column::U8(v)) => {
                v[cell] = if var.name == "n_components" {
                    components.len().min(u8::MAX as usize) as u8
                } else {
                    status
                };
            }
            (Kind::CellValue, Column::F64(v)) => {
                v[cell] = if var.name == "kappa" { kappa } else { energy };
            }
            (Kind::Value, Column::F64(v)) => {
                for (slot, c) in components.iter().take(COMPONENT_SLOTS).enumerate() {
                    v[cell * COMPONENT_SLOTS + slot] = (var.value)(c);
                }
            }
            (Kind::Flag, Column::U8(v)) => {
                for (slot, c) in components.iter().take(COMPONENT_SLOTS).enumerate() {
                    let x = (var.value)(c);
                    v[cell * COMPONENT_SLOTS + slot] = if x.is_nan() { FLAG_FILL } else { x as u8 };
                }
            }
            _ => unreachable!("a column matches its variable's kind"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_the_solver_refuses_is_marked_failed_and_the_block_goes_on() {
        let body = crate::EllipsoidBody::ellipsoid(0.5, 3.0, 0.5, 0.5).unwrap();
        let potential = EffectivePotential::new(&body, 0.8);
        let variables = variables(&Field::ALL);
        let mut block = Block::empty(&variables, 3);
        let options = CellOptions::default();
        // A NaN energy makes the solver return an error; the cells around it are solved.
        for (cell, energy) in [2.5, f64::NAN, 0.1].into_iter().enumerate() {
            fill_cell(&mut block, &variables, cell, (0.8, energy), || {
                solve_level(&potential, energy, &options)
            });
        }
        let status = block.flags(&variables, "cell_status").unwrap();
        assert_eq!(
            status,
            &[cell_status::OK, cell_status::FAILED, cell_status::NO_MOTION]
        );
        let count = block.flags(&variables, "n_components").unwrap();
        assert_eq!(count, &[1, 0, 0]);
        let Column::F64(n) = &block.columns[variables
            .iter()
            .position(|v| v.name == "rotation_number")
            .unwrap()]
        else {
            panic!("rotation_number is f64")
        };
        assert!(n[0].is_finite() && n[3..].iter().all(|x| x.is_nan()));
    }

    #[test]
    fn units_cover_the_grid_once_and_shards_partition_them() {
        let shape = [2, 3, 50, 100];
        let all = units(shape);
        let cells: usize = all.iter().map(|u| u.rows.len() * shape[3]).sum();
        assert_eq!(cells, 2 * 3 * 50 * 100);
        for count in 1..7 {
            let mut seen = vec![0; all.len()];
            for index in 1..=count {
                for u in (Shard { index, count }).units(all.len()) {
                    seen[u] += 1;
                }
            }
            assert!(seen.iter().all(|&s| s == 1));
        }
        assert!(Shard::parse("0/3").is_err());
        assert!(Shard::parse("4/3").is_err());
        assert!(Shard::parse("x").is_err());
        assert_eq!(Shard::parse("2/3").unwrap(), Shard { index: 2, count: 3 });
    }
}
