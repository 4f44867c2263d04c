//! The grid driver: splits a scene's grid into work units (blocks of κ-rows of one (α, β)
//! slice), computes them with rayon one κ-row at a time, and lays the results out as the
//! dense per-cell and per-component arrays of the atlas file (docs/files.md).

use crate::body::{Body, Shape};
use crate::cell::{
    high_energy_families, solve_high_energy_limit, solve_level, CellResult, ComponentResult, Status,
};
use crate::cf::{self, Units};
use crate::error::{AtlasError, Result};
use crate::family::{Census, ComponentAxis, Family};
use crate::scene::{Field, Plane, Scene};
use crate::torus::{EffectivePotential, MotionKind, ScanTable};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};
use std::ops::Range;

/// Component slots per cell in the θ_min layout before the census trims them. {V ≤ ε} has
/// one component per well of V, and V has at most two minima for an ellipsoid of revolution
/// (paper §4: σ_s0 and σ_sπ of type (c); θ* and its mirror at κ = 0); the third slot is a
/// margin. A cell with more components is marked `failed` and keeps its first three.
pub const COMPONENT_SLOTS: usize = 3;

/// Cells per work unit, about: the unit of resume and of sharding.
const UNIT_CELLS: usize = 4096;

/// A cell's status (`cell_status`): motion, no motion, the solver failed on it, or it was
/// never computed (the file's fill value for units not yet written: a finished file, whole
/// or shard, computes every cell it holds).
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
    pub const REACHES_FACE: u8 = 5;
    pub const VALUES: [u8; 6] = [
        OK,
        TOLERANCE_NOT_REACHED,
        FIXED_POINT,
        SEPARATRIX,
        HIGH_ENERGY_LIMIT,
        REACHES_FACE,
    ];
    pub const MEANINGS: &str =
        "ok tolerance_not_reached fixed_point separatrix high_energy_limit reaches_face";
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

/// The long name and units of a coordinate of the cells: the body's α, β, ν, η, the level's
/// κ and ε, and the component slot (the atlas file's coordinates, and the Python package's).
pub fn coordinate(name: &str) -> Option<(&'static str, Units)> {
    Some(match name {
        "alpha" => ("alpha, centre-of-mass offset a/b3", cf::NUMBER),
        "beta" => ("beta, semi-axis ratio b1/b3", cf::NUMBER),
        "cut" => ("cut h of the ball (plane z = -h)", cf::NUMBER),
        "nu" => ("nu, inertia ratio i3/i1", cf::NUMBER),
        "eta" => ("eta = m b3^2/i1", cf::NUMBER),
        "kappa" => ("kappa, integral F2", cf::PAPER),
        "energy" => ("energy", cf::ENERGY),
        "component" => ("component (torus family, or rank in theta_min)", cf::NUMBER),
        _ => return None,
    })
}

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

    /// Bytes per cell of a variable of this kind with `slots` component slots,
    /// uncompressed.
    pub fn bytes_per_cell(self, slots: usize) -> usize {
        let value = match self {
            Kind::Value | Kind::CellValue => 8,
            Kind::Flag | Kind::CellFlag => 1,
        };
        if self.per_cell() {
            value
        } else {
            value * slots
        }
    }

    /// Values per cell with `slots` component slots.
    pub fn values_per_cell(self, slots: usize) -> usize {
        if self.per_cell() {
            1
        } else {
            slots
        }
    }
}

/// One variable of the atlas file.
#[derive(Debug, Clone)]
pub struct Variable {
    pub name: &'static str,
    pub kind: Kind,
    pub long_name: &'static str,
    pub units: Units,
    /// `flag_values` and `flag_meanings` for flag variables.
    pub flags: Option<(&'static [u8], &'static str)>,
    value: fn(&ComponentResult) -> f64,
}

/// The meaning of [`FLAG_FILL`] in a per-component flag: no component in this slot, or (for
/// `bounded`) no verdict.
pub const FLAG_FILL_MEANING: &str = "no_value";

impl Variable {
    /// The CF `flag_values` and `flag_meanings` as the files carry them: a per-component
    /// flag has [`FLAG_FILL`] as a value of its own ([`FLAG_FILL_MEANING`]), so that it
    /// needs no _FillValue and stays an integer in xarray.
    pub fn flag_attributes(&self) -> Option<(Vec<u8>, String)> {
        let (values, meanings) = self.flags?;
        let mut values = values.to_vec();
        let mut meanings = meanings.to_string();
        if self.kind == Kind::Flag {
            values.push(FLAG_FILL);
            meanings.push(' ');
            meanings.push_str(FLAG_FILL_MEANING);
        }
        Some((values, meanings))
    }
}

fn float(
    name: &'static str,
    long_name: &'static str,
    units: Units,
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
        units: cf::NUMBER,
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
            long_name: coordinate(name).expect("kappa or energy").0,
            units: coordinate(name).expect("kappa or energy").1,
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
            long_name: "number of tori",
            units: cf::NUMBER,
            flags: None,
            value: |_| 0.0,
        },
        Variable {
            name: "cell_status",
            kind: Kind::CellFlag,
            long_name: "status of the cell",
            units: cf::NUMBER,
            flags: Some((&cell_status::VALUES, cell_status::MEANINGS)),
            value: |_| 0.0,
        },
        flag(
            "family",
            "torus family",
            (&Family::VALUES, Family::MEANINGS),
            |c| f64::from(c.family.code()),
        ),
    ];
    for &field in fields {
        let (var, error): (Variable, Option<Variable>) = match field {
            Field::ThetaMin => (
                float("theta_min", "theta_min", cf::ANGLE, |c| c.theta_min),
                None,
            ),
            Field::ThetaMax => (
                float("theta_max", "theta_max", cf::ANGLE, |c| c.theta_max),
                None,
            ),
            Field::Period => (
                float("period", "period T", cf::TIME, |c| c.period),
                Some(float("period_error", "error of T", cf::TIME, |c| {
                    c.errors.period
                })),
            ),
            Field::OmegaTheta => (
                float("omega_theta", "frequency omega_theta", cf::RATE, |c| {
                    c.omega_theta
                }),
                Some(float(
                    "omega_theta_error",
                    "error of omega_theta",
                    cf::RATE,
                    |c| c.errors.omega_theta,
                )),
            ),
            Field::OmegaPsi => (
                float("omega_psi", "precession rate omega_psi", cf::RATE, |c| {
                    c.omega_psi
                }),
                Some(float(
                    "omega_psi_error",
                    "error of omega_psi",
                    cf::RATE,
                    |c| c.errors.omega_psi,
                )),
            ),
            Field::RotationNumber => (
                float("rotation_number", "rotation number N", cf::NUMBER, |c| {
                    c.rotation_number
                }),
                None,
            ),
            Field::Drift => (
                float("drift", "drift per period", cf::LENGTH, |c| c.drift),
                Some(float("drift_error", "error of drift", cf::LENGTH, |c| {
                    c.errors.drift
                })),
            ),
            Field::DriftRadius => (
                float("drift_radius", "drift radius R", cf::LENGTH, |c| {
                    c.drift_radius
                }),
                Some(float("drift_radius_error", "error of R", cf::LENGTH, |c| {
                    c.errors.drift_radius
                })),
            ),
            Field::Bounded => (
                flag(
                    "bounded",
                    "path bounded",
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
                    "kind of motion",
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
                    "status",
                    (&status_flag::VALUES, status_flag::MEANINGS),
                    |c| {
                        f64::from(match c.status {
                            Status::Ok | Status::NoMotion => status_flag::OK,
                            Status::ToleranceNotReached => status_flag::TOLERANCE_NOT_REACHED,
                            Status::FixedPoint => status_flag::FIXED_POINT,
                            Status::Separatrix => status_flag::SEPARATRIX,
                            Status::HighEnergyLimit => status_flag::HIGH_ENERGY_LIMIT,
                            Status::ReachesFace => status_flag::REACHES_FACE,
                        })
                    },
                ),
                None,
            ),
            Field::ErrorEstimate => (
                float("error_estimate", "error of N", cf::NUMBER, |c| {
                    c.error_estimate
                }),
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
    fn new(kind: Kind, len: usize, slots: usize) -> Column {
        match kind {
            Kind::Value => Column::F64(vec![f64::NAN; len * slots]),
            Kind::Flag => Column::U8(vec![FLAG_FILL; len * slots]),
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
    /// Component slots per cell.
    pub slots: usize,
    pub columns: Vec<Column>,
}

impl Block {
    /// A block of `cells` cells with `slots` component slots, every value at its fill.
    pub fn empty(variables: &[Variable], cells: usize, slots: usize) -> Block {
        Block {
            cells,
            slots,
            columns: variables
                .iter()
                .map(|v| Column::new(v.kind, cells, slots))
                .collect(),
        }
    }

    /// The blocks one after the other (allocated once: growing by appends would leave the
    /// heap fragmented with slice-sized holes).
    pub fn concat(variables: &[Variable], slots: usize, blocks: Vec<Block>) -> Block {
        let cells: usize = blocks.iter().map(|b| b.cells).sum();
        let mut columns: Vec<Column> = variables
            .iter()
            .map(|v| {
                let n = cells * v.kind.values_per_cell(slots);
                match v.kind {
                    Kind::Value | Kind::CellValue => Column::F64(Vec::with_capacity(n)),
                    Kind::Flag | Kind::CellFlag => Column::U8(Vec::with_capacity(n)),
                }
            })
            .collect();
        for b in blocks {
            debug_assert_eq!(b.slots, slots);
            for (a, c) in columns.iter_mut().zip(b.columns) {
                a.append(c);
            }
        }
        Block {
            cells,
            slots,
            columns,
        }
    }

    /// The block with only the component slots `keep` (in that order).
    pub fn select_slots(self, variables: &[Variable], keep: &[usize]) -> Block {
        let slots = self.slots;
        let pick = |len: usize| {
            (0..len / slots).flat_map(move |cell| keep.iter().map(move |&k| cell * slots + k))
        };
        let columns = variables
            .iter()
            .zip(self.columns)
            .map(|(v, column)| match (v.kind.per_cell(), column) {
                (true, c) => c,
                (false, Column::F64(x)) => Column::F64(pick(x.len()).map(|i| x[i]).collect()),
                (false, Column::U8(x)) => Column::U8(pick(x.len()).map(|i| x[i]).collect()),
            })
            .collect();
        Block {
            cells: self.cells,
            slots: keep.len(),
            columns,
        }
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

/// A work unit: rows `rows` of κ of the slices (α_{ia}, β_{ib}) for ib in `betas` (several
/// β only where a slice is smaller than a unit, and then with every row).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unit {
    /// Position in [`units`].
    pub index: usize,
    pub alpha_index: usize,
    pub betas: Range<usize>,
    pub rows: Range<usize>,
}

impl Unit {
    /// The unit's cells in a grid of `columns` ε values.
    pub fn cells(&self, columns: usize) -> usize {
        self.betas.len() * self.rows.len() * columns
    }
}

/// κ-rows per work unit: about [`UNIT_CELLS`] cells. A unit is also one chunk of the file.
pub fn rows_per_unit(shape: [usize; 4]) -> usize {
    let [_, _, nk, ne] = shape;
    UNIT_CELLS.div_ceil(ne.max(1)).clamp(1, nk.max(1))
}

/// β values per work unit: 1, or where a whole slice is under [`SMALL_SLICE`] cells as many
/// slices as make [`UNIT_CELLS`] (a grid of one-cell slices wrote a chunk and a journal file
/// per cell: 2 kB of file and 200 µs a cell).
pub fn betas_per_unit(shape: [usize; 4]) -> usize {
    let [_, nb, nk, ne] = shape;
    let slice = nk.max(1) * ne.max(1);
    if slice >= SMALL_SLICE {
        return 1;
    }
    (UNIT_CELLS / slice).clamp(1, nb.max(1))
}

/// Slices of fewer cells are grouped into units of several β ([`betas_per_unit`]); larger
/// ones keep one slice a unit, so that shards can still split β (and the files of earlier
/// builds keep their chunks).
const SMALL_SLICE: usize = UNIT_CELLS / 16;

/// The number of work units of a grid of shape `shape` (see [`unit`]).
pub fn unit_count(shape: [usize; 4]) -> usize {
    let [na, _, nk, _] = shape;
    na * Region::positions(shape)[1] * nk.div_ceil(rows_per_unit(shape))
}

/// Work unit `index` of the grid's units, group of slices after group (α slowest), each of
/// about [`UNIT_CELLS`] cells (whole κ-rows of one slice, or whole slices of consecutive β).
/// The split depends on the grid alone, never on threads or shards. Made on demand: a grid
/// of many slices has many units.
pub fn unit(shape: [usize; 4], index: usize) -> Unit {
    let [_, nb, nk, _] = shape;
    let rows_per_unit = rows_per_unit(shape);
    let betas_per_unit = betas_per_unit(shape);
    let per_group = nk.div_ceil(rows_per_unit);
    let groups = nb.div_ceil(betas_per_unit);
    let (group, block) = (index / per_group, index % per_group);
    let (start, first_beta) = (block * rows_per_unit, (group % groups) * betas_per_unit);
    Unit {
        index,
        alpha_index: group / groups,
        betas: first_beta..(first_beta + betas_per_unit).min(nb),
        rows: start..(start + rows_per_unit).min(nk),
    }
}

/// The grid's work units in order ([`unit`]).
pub fn units(shape: [usize; 4]) -> impl Iterator<Item = Unit> {
    (0..unit_count(shape)).map(move |i| unit(shape, i))
}

/// The divisors of `n` in increasing order (O(√n): shard counts may be large).
fn divisors(n: usize) -> Vec<usize> {
    let mut low = Vec::new();
    let mut high = Vec::new();
    let mut i = 1;
    while i <= n / i {
        if n.is_multiple_of(i) {
            low.push(i);
            if i != n / i {
                high.push(n / i);
            }
        }
        i += 1;
    }
    low.extend(high.into_iter().rev());
    low
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
        let whole = |part: &str, name: &str| -> Result<usize> {
            part.trim().parse().map_err(|e: std::num::ParseIntError| {
                use std::num::IntErrorKind::PosOverflow;
                bad(&if *e.kind() == PosOverflow {
                    format!("{name} is beyond {}", usize::MAX)
                } else {
                    format!("{name} is not a whole number >= 1")
                })
            })
        };
        let (index, count) = (whole(i, "I")?, whole(n, "N")?);
        if count == 0 || index == 0 || index > count {
            return Err(bad("needs 1 <= I <= N"));
        }
        Ok(Shard { index, count })
    }

    /// How a grid of shape `shape` is cut into this many shards: the counts along α, β and
    /// the blocks of κ-rows (work units never straddle two shards), whose product is the
    /// shard count. Of the ways to factor the count, the one whose largest shard has the
    /// fewest units (slower axes first on a tie). None where the count does not factor
    /// over the axes' lengths (e.g. 3 shards of a 2 × 2 × 1 grid).
    pub fn layout(&self, shape: [usize; 4]) -> Option<[usize; 3]> {
        let lengths = Region::positions(shape);
        let n = self.count;
        let mut best: Option<(usize, [usize; 3])> = None;
        // Larger counts of the slower axes first: the first of equal layouts is kept.
        for a in divisors(n).into_iter().rev().filter(|&a| a <= lengths[0]) {
            for b in divisors(n / a)
                .into_iter()
                .rev()
                .filter(|&b| b <= lengths[1])
            {
                let k = n / a / b;
                if k > lengths[2] {
                    continue;
                }
                let counts = [a, b, k];
                let largest: usize = (0..3).map(|i| lengths[i].div_ceil(counts[i])).product();
                if best.is_none_or(|(l, _)| largest < l) {
                    best = Some((largest, counts));
                }
            }
        }
        best.map(|(_, counts)| counts)
    }

    /// The part of a grid of shape `shape` that belongs to this shard: a box of the
    /// [`Shard::layout`], shards numbered with α slowest. Shard files hold just their
    /// region, so that xarray combines them by coordinates. The shard must have passed
    /// [`Shard::check_against`].
    pub fn region(&self, shape: [usize; 4]) -> Region {
        let counts = self
            .layout(shape)
            .expect("a shard checked against its grid");
        let lengths = Region::positions(shape);
        let mut rest = self.index - 1;
        let mut ranges = [0..0, 0..0, 0..0];
        for axis in (0..3).rev() {
            let i = rest % counts[axis];
            rest /= counts[axis];
            // In 128 bits: positions · index does not overflow for any usize shard.
            let at = |i: usize| (lengths[axis] as u128 * i as u128 / counts[axis] as u128) as usize;
            ranges[axis] = at(i)..at(i + 1);
        }
        let (rows, betas) = (rows_per_unit(shape), betas_per_unit(shape));
        let [alpha, groups, blocks] = ranges;
        Region {
            alpha,
            beta: groups.start * betas..(groups.end * betas).min(shape[1]),
            rows: blocks.start * rows..(blocks.end * rows).min(shape[2]),
            columns: shape[3],
        }
    }

    /// This shard's work units (among the grid's [`units`]), in their order, made on demand.
    pub fn units(&self, shape: [usize; 4]) -> impl Iterator<Item = Unit> {
        let region = self.region(shape);
        let rows_per_unit = rows_per_unit(shape);
        let per_group = shape[2].div_ceil(rows_per_unit);
        let blocks = region.rows.start / rows_per_unit..region.rows.end.div_ceil(rows_per_unit);
        let groups = region.groups(shape);
        let per_alpha = Region::positions(shape)[1];
        region.alpha.clone().flat_map(move |ia| {
            let blocks = blocks.clone();
            groups.clone().flat_map(move |g| {
                blocks
                    .clone()
                    .map(move |b| unit(shape, (ia * per_alpha + g) * per_group + b))
            })
        })
    }

    /// Checks that the grid of shape `shape` splits into this many shards: boxes, one per
    /// shard, each with work of its own. `second` names the grid's second axis (`beta`,
    /// `cut`; None for the disk's grid, which has none) for the message.
    pub fn check_against(&self, shape: [usize; 4], second: Option<&str>) -> Result<()> {
        if self.index == 0 || self.index > self.count {
            return Err(AtlasError::Atlas {
                path: format!("shard {self}"),
                reason: "needs 1 <= I <= N".into(),
            });
        }
        if self.layout(shape).is_none() {
            let [a, b, k] = Region::positions(shape);
            let fits = (1..=self.count.min(a * b * k))
                .rev()
                .find(|&n| Shard { index: 1, count: n }.layout(shape).is_some())
                .unwrap_or(1);
            let (boxes, factors) = match second {
                Some(name) => (
                    format!("{a} alpha x {b} {name} x {k}"),
                    format!("{a}, {b} and {k}"),
                ),
                None => (format!("{a} alpha x {k}"), format!("{a} and {k}")),
            };
            return Err(AtlasError::Atlas {
                path: format!("shard {self}"),
                reason: format!(
                    "shards are boxes of the grid, and {} shards do not tile its {boxes} \
                     blocks of kappa rows: use a count that is a product of at most \
                     {factors} (e.g. {fits})",
                    self.count
                ),
            });
        }
        Ok(())
    }
}

/// A box of the grid: ranges of α, β and κ-row indices, with every ε. A whole atlas is one
/// region; a shard file holds the region of its shard.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Region {
    pub alpha: Range<usize>,
    pub beta: Range<usize>,
    pub rows: Range<usize>,
    /// Columns (ε), always all of them.
    pub columns: usize,
}

impl Region {
    /// The whole grid of shape `shape`.
    pub fn whole(shape: [usize; 4]) -> Region {
        let [na, nb, nk, ne] = shape;
        Region {
            alpha: 0..na,
            beta: 0..nb,
            rows: 0..nk,
            columns: ne,
        }
    }

    /// The region's own shape (α, β, κ, ε).
    pub fn shape(&self) -> [usize; 4] {
        [
            self.alpha.len(),
            self.beta.len(),
            self.rows.len(),
            self.columns,
        ]
    }

    /// (β, κ-rows) per chunk of a file of this region of a grid of shape `grid`: a work
    /// unit's (each unit is one chunk), or fewer where the region has fewer (a chunk may not
    /// be larger than its dataset).
    pub fn chunk(&self, grid: [usize; 4]) -> [usize; 2] {
        [
            betas_per_unit(grid).min(self.beta.len()).max(1),
            rows_per_unit(grid).min(self.rows.len()).max(1),
        ]
    }

    /// Cells per chunk of every variable ([`Region::chunk`]).
    pub fn chunk_cells(&self, grid: [usize; 4]) -> usize {
        let [betas, rows] = self.chunk(grid);
        betas * rows * self.columns
    }

    /// The groups of β (of [`betas_per_unit`] each) this region spans.
    fn groups(&self, grid: [usize; 4]) -> Range<usize> {
        let betas = betas_per_unit(grid);
        self.beta.start / betas..self.beta.end.div_ceil(betas)
    }

    /// The work units in this region of a grid of shape `grid`.
    pub fn unit_count(&self, grid: [usize; 4]) -> usize {
        let rows_per_unit = rows_per_unit(grid);
        let blocks = self.rows.end.div_ceil(rows_per_unit) - self.rows.start / rows_per_unit;
        self.alpha.len() * self.groups(grid).len() * blocks
    }

    /// Whether `unit` lies in this region (units never straddle shards' regions).
    pub fn holds(&self, unit: &Unit) -> bool {
        self.alpha.contains(&unit.alpha_index)
            && self.beta.contains(&unit.betas.start)
            && self.rows.contains(&unit.rows.start)
    }

    /// The positions shards can split a grid of shape `shape` at: its α values, groups of β
    /// values (one each but where slices are small) and blocks of κ-rows (one work unit each
    /// per group).
    pub fn positions(shape: [usize; 4]) -> [usize; 3] {
        let [na, nb, nk, _] = shape;
        [
            na,
            nb.div_ceil(betas_per_unit(shape)),
            nk.div_ceil(rows_per_unit(shape)),
        ]
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// How one cell of a scene's grid is solved: at its level of V, or (s = 0 of the compact
/// plane) in the high-energy limit at its λ.
enum CellLevel<'p, 'b, S: Shape> {
    Level(&'p EffectivePotential<'b, S>, f64),
    HighEnergy(f64),
}

/// Visits the cells of κ-row `row` of a scene's slice with body `body`, column by column:
/// `visit(column, (κ, ε), level)`. Every cell's κ and ε are formed here alone, for the
/// census and the computation alike.
fn visit_row<S: Shape>(
    scene: &Scene,
    body: &Body<S>,
    row: usize,
    mut visit: impl FnMut(usize, (f64, f64), CellLevel<'_, '_, S>),
) {
    let row_value = scene.kappa.values[row];
    let columns = &scene.energy.values;
    match scene.plane {
        Plane::KappaEnergy | Plane::KappaExcess => {
            let potential = EffectivePotential::new(body, row_value);
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
                visit(j, (row_value, energy), CellLevel::Level(&potential, energy));
            }
        }
        Plane::Compact => {
            // κ = λ/s, ε = 1/s²: every cell has its own κ; s = 0 is ε = ∞.
            let table = ScanTable::new(body);
            for (j, &s) in columns.iter().enumerate() {
                if s == 0.0 {
                    // λ = 0 keeps κ = 0 at ε = ∞ (rolling over the top), as at every s > 0.
                    let kappa = if row_value == 0.0 { 0.0 } else { f64::INFINITY };
                    visit(j, (kappa, f64::INFINITY), CellLevel::HighEnergy(row_value));
                } else {
                    let (kappa, energy) = (row_value / s, 1.0 / (s * s));
                    let potential = EffectivePotential::with_scan(body, kappa, &table);
                    visit(j, (kappa, energy), CellLevel::Level(&potential, energy));
                }
            }
        }
    }
}

/// What the whole grid of `scene` holds (the families and the most components of a cell),
/// from V's critical points alone, rows shared out by rayon: enough to lay out the
/// component axis before any cell is computed. The same for every shard of the grid. In the
/// family layout it ends as soon as it has found every family the scene's bodies can have
/// ([`crate::family::possible_for_ellipsoid`]): on planes where every cell has its own κ
/// (λ, s) the critical points are the bulk of a cell's cost, and a full census would double
/// it.
pub fn census(scene: &Scene, stop: &(dyn Fn() -> bool + Sync)) -> Census {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Mutex;
    let [na, nb, nk, _] = scene.shape();
    let kappa_zero = scene.kappa.values.contains(&0.0);
    // (Over every body of a grid of up to 1e12 of them: `stop` is heard between bodies, and
    // the pass ends once every family is possible; it used to run on, deaf to Ctrl-C and
    // SIGTERM for minutes, at 1e6 × 1e6 bodies: an adversary pass.)
    let ceiling = Family::mask(Family::possible_for(scene.shape.as_ref()));
    let mut possible = [false; Family::ALL.len()];
    'bodies: for &alpha in &scene.alpha.values {
        for &second in &scene.second.values {
            if possible == ceiling || stop() {
                break 'bodies;
            }
            // An edged body's families are not told in advance: the census is whole.
            let body = match scene.shape {
                None => crate::family::possible_for_ellipsoid(alpha, second, kappa_zero),
                Some(_) => ceiling,
            };
            for (p, b) in possible.iter_mut().zip(body) {
                *p |= b;
            }
        }
    }
    let early = scene.layout == crate::family::Layout::Family;
    let found = Mutex::new(Census::default());
    let done = AtomicBool::new(false);
    // (`try_for_each` ends the whole iteration at the first `Err`; `for_each` visited every
    // remaining item, each returning at once, which over 1e12 rows took hours after Ctrl-C.)
    let _ = (0..na * nb * nk)
        .into_par_iter()
        .with_max_len(1)
        .try_for_each(|i| {
            if done.load(Ordering::Relaxed) || stop() {
                return Err(());
            }
            let (slice, row) = (i / nk, i % nk);
            let body = scene.body(slice / nb, slice % nb);
            let mut census = Census::default();
            crate::with_body!(&body, body => visit_row(scene, body, row, |_, _, level| {
                census.add(&match level {
                    CellLevel::Level(potential, energy) => {
                        potential.families(energy).unwrap_or_default()
                    }
                    CellLevel::HighEnergy(lambda) => high_energy_families(body, lambda),
                });
            }));
            let mut all = found.lock().expect("no census panics");
            *all = all.merge(census);
            if early && all.covers(&possible) {
                done.store(true, Ordering::Relaxed);
            }
            Ok(())
        });
    found.into_inner().expect("no census panics")
}

/// The component axis of `scene`'s file: its layout over the families and counts its
/// [`census`] finds (cut short, and then meaningless, once `stop` says so).
pub fn component_axis(scene: &Scene, stop: &(dyn Fn() -> bool + Sync)) -> ComponentAxis {
    ComponentAxis::of(scene.layout, &census(scene, stop))
}

/// Computes the κ-rows `rows` (in that order) of the slices (ia, ib), ib in `betas` (the
/// second shape parameter, slowest), rows shared out by rayon one at a time (rows differ
/// several-fold in cost), into the slots of `axis`; `progress` is called with the number of cells after each row. Every
/// cell is computed on its own, so the values do not depend on the number of threads or on
/// which rows are computed together.
#[allow(clippy::too_many_arguments)]
pub fn compute_rows(
    scene: &Scene,
    variables: &[Variable],
    axis: &ComponentAxis,
    alpha_index: usize,
    betas: Range<usize>,
    rows: &[usize],
    progress: &(dyn Fn(usize) + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Option<Block> {
    let bodies: Vec<_> = betas.map(|ib| scene.body(alpha_index, ib)).collect();
    let columns = scene.energy.values.len();
    let options = &scene.options;
    let jobs: Vec<(usize, usize)> = (0..bodies.len())
        .flat_map(|b| rows.iter().map(move |&row| (b, row)))
        .collect();
    let blocks: Vec<Block> = jobs
        .par_iter()
        .with_max_len(1)
        .map(|&(b, row)| {
            let mut block = Block::empty(variables, columns, axis.len());
            crate::with_body!(&bodies[b], body => visit_row(scene, body, row, |j, point, level| {
                // Asked to stop: the rest of the unit is skipped (and the unit dropped), so
                // that slow cells (a profile of many points: 30 ms each) do not hold the run.
                if stop() {
                    return;
                }
                fill_cell(&mut block, variables, axis, j, point, || match level {
                    CellLevel::Level(potential, energy) => solve_level(potential, energy, options),
                    CellLevel::HighEnergy(lambda) => solve_high_energy_limit(body, lambda, options),
                });
            }));
            progress(columns);
            block
        })
        .collect();
    (!stop()).then(|| Block::concat(variables, axis.len(), blocks))
}

/// One cell given by all its numbers: the body (α, β, ν, η) and the level (κ, ε).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellPoint {
    pub alpha: f64,
    pub beta: f64,
    pub nu: f64,
    pub eta: f64,
    pub kappa: f64,
    pub energy: f64,
}

/// Cells computed in this many at a time per rayon task.
const POINTS_PER_TASK: usize = 64;

/// The ellipsoids of `points` ([`bodies_of`] with α, β, ν, η).
pub fn cell_bodies(points: &[CellPoint]) -> Result<Vec<crate::EllipsoidBody>> {
    bodies_of(points, |p| {
        crate::EllipsoidBody::ellipsoid(p.alpha, p.beta, p.nu, p.eta)
    })
}

/// The bodies of `points`, made by `make` (an edged body takes its cut from `beta`), each
/// point checked: a bad one is refused, naming its index and value.
pub fn bodies_of<S: Shape>(
    points: &[CellPoint],
    make: impl Fn(&CellPoint) -> Result<Body<S>>,
) -> Result<Vec<Body<S>>> {
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let at = |e: AtlasError| AtlasError::Atlas {
                path: format!("cell {i}"),
                reason: e.to_string(),
            };
            crate::error::check_kappa(p.kappa).map_err(at)?;
            crate::error::check_energy(p.energy).map_err(at)?;
            make(p).map_err(at)
        })
        .collect()
}

/// Computes `points` with their `bodies` ([`cell_bodies`]) on the current rayon pool, into
/// one block laid out as the atlas file lays out a row (the Python package's `cells`). Each
/// cell is solved as `rubber-atlas cell` and `run` solve it, so the values are the same bit
/// for bit. Given up when `stop` says so (polled between cells): then an empty block.
pub fn compute_cells<S: Shape>(
    points: &[CellPoint],
    bodies: &[Body<S>],
    variables: &[Variable],
    axis: &ComponentAxis,
    options: &crate::cell::CellOptions,
    stop: &(dyn Fn() -> bool + Sync),
) -> Block {
    let blocks: Vec<Block> = points
        .par_chunks(POINTS_PER_TASK)
        .zip(bodies.par_chunks(POINTS_PER_TASK))
        .map(|(points, bodies)| {
            // Asked to stop: nothing more is allocated or solved.
            if stop() {
                return Block::empty(variables, 0, axis.len());
            }
            let mut block = Block::empty(variables, points.len(), axis.len());
            visit_with_potentials(points, bodies, |j, p, potential| {
                // Asked to stop: the rest stays fill (the caller drops the block).
                if stop() {
                    return false;
                }
                fill_cell(&mut block, variables, axis, j, (p.kappa, p.energy), || {
                    solve_level(potential, p.energy, options)
                });
                true
            });
            block
        })
        .collect();
    if stop() {
        return Block::empty(variables, 0, axis.len());
    }
    Block::concat(variables, axis.len(), blocks)
}

/// Visits `points` (with `bodies`) in order, each with V at its κ: `visit(index, point, V)`
/// until it returns false. Consecutive points of one body and κ (a row of a grid) share V's
/// critical points, as the cells of an atlas row do: found once.
fn visit_with_potentials<S: Shape>(
    points: &[CellPoint],
    bodies: &[Body<S>],
    mut visit: impl FnMut(usize, &CellPoint, &EffectivePotential<'_, S>) -> bool,
) {
    let key = |q: &CellPoint| [q.alpha, q.beta, q.nu, q.eta, q.kappa].map(f64::to_bits);
    // The body's part of the scan, kept while the body stays (κ alone varying along a path).
    let mut table: Option<([u64; 4], ScanTable)> = None;
    let mut row: Option<([u64; 5], EffectivePotential<'_, S>)> = None;
    for (j, (p, body)) in points.iter().zip(bodies).enumerate() {
        if row.as_ref().is_none_or(|(k, _)| *k != key(p)) {
            let body_key = [p.alpha, p.beta, p.nu, p.eta].map(f64::to_bits);
            if table.as_ref().is_none_or(|(k, _)| *k != body_key) {
                table = Some((body_key, ScanTable::new(body)));
            }
            let scan = &table.as_ref().expect("set above").1;
            row = Some((key(p), EffectivePotential::with_scan(body, p.kappa, scan)));
        }
        if !visit(j, p, &row.as_ref().expect("set above").1) {
            return;
        }
    }
}

/// The most components of {V ≤ ε} at any one of `points` (with `bodies`), from V's
/// critical points alone (as [`census`] counts them for a grid): the θ_min layout's room for
/// cells of bodies whose wells are not known in advance (a profile may have any number).
/// `stop` is heard between chunks (the count is then meaningless).
pub fn most_components<S: Shape>(
    points: &[CellPoint],
    bodies: &[Body<S>],
    stop: &(dyn Fn() -> bool + Sync),
) -> usize {
    points
        .par_chunks(POINTS_PER_TASK)
        .zip(bodies.par_chunks(POINTS_PER_TASK))
        .map(|(points, bodies)| {
            if stop() {
                return 0;
            }
            let mut most = 0;
            visit_with_potentials(points, bodies, |_, p, potential| {
                most = most.max(potential.families(p.energy).map_or(0, |f| f.len()));
                true
            });
            most
        })
        .max()
        .unwrap_or(0)
}

/// The middle of a component's θ-range on the circle, in (−π, π]: at κ = 0 the angles are
/// lifted (θ up to 3π), so a mirror image at θ < 0 may be held as one beyond π.
fn leaning_angle(c: &ComponentResult) -> f64 {
    let mid = 0.5 * (c.theta_min + c.theta_max);
    let wrapped = mid - TAU * (mid / TAU).round();
    if wrapped <= -PI {
        wrapped + TAU
    } else {
        wrapped
    }
}

/// One cell of `block`: `solve` gives its components, laid out in the slots of `axis`;
/// `(kappa, energy)` are its κ and ε, written where they are auxiliary coordinates. The cell
/// is marked `failed` (keeping what fits) where a component has no slot, or where two
/// components of one family meet away from κ = 0; at κ = 0 the mirror images of one family
/// (the body leaning either way) share its slot, and the one leaning to θ > 0 is kept
/// ([`leaning_angle`]), the one continuous with κ > 0.
pub fn fill_cell(
    block: &mut Block,
    variables: &[Variable],
    axis: &ComponentAxis,
    cell: usize,
    (kappa, energy): (f64, f64),
    solve: impl FnOnce() -> Result<CellResult>,
) {
    // A panic in the solver is a bug, but one cell must not end a run of millions: it is
    // recorded as a failed cell.
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(solve));
    let (mut status, components) = match result {
        Ok(Ok(c)) if c.status == Status::NoMotion => (cell_status::NO_MOTION, Vec::new()),
        Ok(Ok(c)) => (cell_status::OK, c.components),
        Ok(Err(_)) | Err(_) => (cell_status::FAILED, Vec::new()),
    };
    let mut placed: Vec<(usize, &ComponentResult)> = Vec::with_capacity(components.len());
    for (index, c) in components.iter().enumerate() {
        match axis.slot(index, c.family) {
            Some(slot) => match placed.iter_mut().find(|(s, _)| *s == slot) {
                Some(twin) if kappa == 0.0 => {
                    if leaning_angle(c) > leaning_angle(twin.1) {
                        twin.1 = c;
                    }
                }
                Some(_) => status = cell_status::FAILED,
                None => placed.push((slot, c)),
            },
            None => status = cell_status::FAILED,
        }
    }
    let slots = axis.len();
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
                for &(slot, c) in &placed {
                    v[cell * slots + slot] = (var.value)(c);
                }
            }
            (Kind::Flag, Column::U8(v)) => {
                for &(slot, c) in &placed {
                    let x = (var.value)(c);
                    v[cell * slots + slot] = if x.is_nan() { FLAG_FILL } else { x as u8 };
                }
            }
            _ => unreachable!("a column matches its variable's kind"),
        }
    }
}
