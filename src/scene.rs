//! Scenes: the TOML files (docs/files.md) that describe an atlas run — the body (its shape, ν,
//! η), the grid axes (the shape's parameters, κ, ε), the solver settings and the outputs
//! wanted. Parsing checks every key and value and names the file, the key and the reason of
//! the first problem it finds.

use crate::body::{second_parameter, shape_name, SHAPE_NAMES};
use crate::cell::{CellOptions, Method};
use crate::error::{show, AtlasError, Result, MAX_ENERGY, MAX_KAPPA};
use crate::family::Layout;
use crate::{AnyBody, EdgedKind};
use std::path::Path;
use toml::{Table, Value};

/// An output variable a scene may ask for (one value per cell and component).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Field {
    ThetaMin,
    ThetaMax,
    Period,
    OmegaTheta,
    OmegaPsi,
    RotationNumber,
    Drift,
    DriftRadius,
    Bounded,
    Motion,
    Status,
    ErrorEstimate,
}

impl Field {
    /// Every field, in the order of the file.
    pub const ALL: [Field; 12] = [
        Field::ThetaMin,
        Field::ThetaMax,
        Field::Period,
        Field::OmegaTheta,
        Field::OmegaPsi,
        Field::RotationNumber,
        Field::Drift,
        Field::DriftRadius,
        Field::Bounded,
        Field::Motion,
        Field::Status,
        Field::ErrorEstimate,
    ];

    /// The variable's name in scenes and in the HDF5 file.
    pub fn name(self) -> &'static str {
        match self {
            Field::ThetaMin => "theta_min",
            Field::ThetaMax => "theta_max",
            Field::Period => "period",
            Field::OmegaTheta => "omega_theta",
            Field::OmegaPsi => "omega_psi",
            Field::RotationNumber => "rotation_number",
            Field::Drift => "drift",
            Field::DriftRadius => "drift_radius",
            Field::Bounded => "bounded",
            Field::Motion => "motion",
            Field::Status => "status",
            Field::ErrorEstimate => "error_estimate",
        }
    }

    /// The field named `name`, if any.
    pub fn from_name(name: &str) -> Option<Field> {
        Field::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Whether the field needs the drift integrals Δζ.
    pub fn needs_drift(self) -> bool {
        matches!(self, Field::Drift | Field::DriftRadius | Field::Bounded)
    }
}

/// One grid axis: strictly increasing, finite values.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    pub values: Vec<f64>,
}

impl Axis {
    /// `num` values from `start` to `stop` inclusive, evenly spaced (the last one exactly
    /// `stop`); `num = 1` needs `start = stop`.
    pub fn linspace(start: f64, stop: f64, num: usize) -> Vec<f64> {
        if num == 1 {
            return vec![start];
        }
        let step = (stop - start) / (num - 1) as f64;
        (0..num)
            .map(|i| {
                if i + 1 == num {
                    stop
                } else {
                    start + step * i as f64
                }
            })
            .collect()
    }

    /// `num` values from `start` to `stop` inclusive, evenly spaced in log (both > 0; the
    /// ends exactly `start` and `stop`).
    pub fn logspace(start: f64, stop: f64, num: usize) -> Vec<f64> {
        let mut v: Vec<f64> = Axis::linspace(start.ln(), stop.ln(), num)
            .into_iter()
            .map(f64::exp)
            .collect();
        v[0] = start;
        if let Some(last) = v.last_mut() {
            *last = stop;
        }
        v
    }

    pub fn len(&self) -> usize {
        self.values.len()
    }

    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

/// The smallest s > 0 of a compactified plane: ε = 1/s² ≤ 1e300.
const MIN_S: f64 = 1e-150;

/// Which two axes span the (κ, ε) plane of each body (docs/files.md and §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plane {
    /// `kappa` and `energy`: κ and ε themselves.
    KappaEnergy,
    /// `kappa` and `excess_energy`: ε = V_min(κ) + e, measured from the bottom of V at each κ
    /// (the deepest minimum), so that no cell falls below the bottom.
    KappaExcess,
    /// `lambda` and `s`: κ = λ/s, ε = 1/s² (λ = κ/√ε, s = 1/√ε). s = 0 is ε = ∞ itself, where
    /// the cells are the high-energy limit N∞(λ) (paper `eqsys` without U); λ ≤ √2 has motion.
    Compact,
}

impl Plane {
    /// The names of the row and the column axis (the file's dimensions 3 and 4).
    pub fn axis_names(self) -> [&'static str; 2] {
        match self {
            Plane::KappaEnergy => ["kappa", "energy"],
            Plane::KappaExcess => ["kappa", "excess_energy"],
            Plane::Compact => ["lambda", "s"],
        }
    }

    /// κ and ε of each cell when they are not axes themselves: the file's 2-D (per slice)
    /// CF auxiliary coordinates.
    pub fn auxiliary(self) -> &'static [&'static str] {
        match self {
            Plane::KappaEnergy => &[],
            Plane::KappaExcess => &["energy"],
            Plane::Compact => &["kappa", "energy"],
        }
    }
}

/// A parsed, validated scene.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The scene's name (default output `atlas/<name>.h5`).
    pub name: String,
    /// The body's shape (`[body] shape`): None for the ellipsoid (the default), or an edged
    /// body (docs/bodies.md).
    pub shape: Option<EdgedKind>,
    /// ν = i3 / i1.
    pub nu: f64,
    /// η = m b3² / i1 (b3 the shape's unit of length).
    pub eta: f64,
    /// The centre-of-mass offset α of every shape.
    pub alpha: Axis,
    /// The shape's second parameter ([`Scene::second_name`]): β of the ellipsoid, the cut h of
    /// the truncated ball and the wheel; the disk has none, and this axis is the one value 0
    /// (the grid keeps four dimensions; its file drops this one).
    pub second: Axis,
    /// The row axis of each slice: κ, or λ for the compactified plane.
    pub kappa: Axis,
    /// The column axis: ε, the excess energy ε − V_min(κ), or s.
    pub energy: Axis,
    /// Which axes the two are.
    pub plane: Plane,
    /// Solver options (tolerance, method; drift only if an output needs it).
    pub options: CellOptions,
    /// The outputs asked for, in file order; `status` is always among them.
    pub fields: Vec<Field>,
    /// How the component axis is laid out (`[outputs] layout`): by torus family (the
    /// default) or by increasing θ_min.
    pub layout: Layout,
    /// The scene file's text, kept verbatim in the atlas for provenance and for resume and
    /// merge to check that they continue the same scene.
    pub text: String,
}

struct Reader<'a> {
    file: &'a str,
}

impl Reader<'_> {
    fn error(&self, key: &str, reason: impl Into<String>) -> AtlasError {
        AtlasError::Scene {
            file: self.file.to_string(),
            key: key.to_string(),
            reason: reason.into(),
        }
    }

    /// Refuses keys of `table` outside `known`.
    fn only_keys(&self, table: &Table, prefix: &str, known: &[&str]) -> Result<()> {
        match table.keys().find(|k| !known.contains(&k.as_str())) {
            Some(k) => Err(self.error(
                &join(prefix, k),
                format!("unknown key (expected one of: {})", known.join(", ")),
            )),
            None => Ok(()),
        }
    }

    fn table<'t>(&self, parent: &'t Table, prefix: &str, key: &str) -> Result<&'t Table> {
        match parent.get(key) {
            Some(Value::Table(t)) => Ok(t),
            Some(v) => Err(self.error(
                &join(prefix, key),
                format!("expected a table, found {}", v.type_str()),
            )),
            None => Err(self.error(&join(prefix, key), "missing")),
        }
    }

    fn number(&self, value: &Value, key: &str) -> Result<f64> {
        let x = match value {
            Value::Float(x) => *x,
            Value::Integer(i) => *i as f64,
            v => return Err(self.error(key, format!("expected a number, found {}", v.type_str()))),
        };
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.error(key, format!("{x} is not a finite number")))
        }
    }

    fn required_number(&self, table: &Table, prefix: &str, key: &str) -> Result<f64> {
        let full = join(prefix, key);
        match table.get(key) {
            Some(v) => self.number(v, &full),
            None => Err(self.error(&full, "missing")),
        }
    }

    /// `[body] profile`: the meridian's table, a list of [rho, z] or [rho, z, edge] rows.
    fn profile(&self, body: &Table) -> Result<&'static crate::body::Profile> {
        let key = "body.profile";
        let rows = match body.get("profile") {
            None => {
                return Err(self.error(
                    key,
                    "missing: shape = \"profile\" needs the meridian's points, [[rho, z], ...]",
                ))
            }
            Some(Value::Array(rows)) => rows,
            Some(v) => {
                return Err(self.error(
                    key,
                    format!("expected a list of [rho, z] rows, found {}", v.type_str()),
                ))
            }
        };
        let rows = rows
            .iter()
            .enumerate()
            .map(|(i, row)| match row {
                Value::Array(values) => values
                    .iter()
                    .enumerate()
                    .map(|(j, v)| self.number(v, &format!("{key}[{i}][{j}]")))
                    .collect::<Result<Vec<f64>>>(),
                v => Err(self.error(
                    &format!("{key}[{i}]"),
                    format!(
                        "expected a row [rho, z] or [rho, z, edge], found {}",
                        v.type_str()
                    ),
                )),
            })
            .collect::<Result<Vec<_>>>()?;
        crate::body::Profile::from_points(&rows).map_err(|e| self.error(key, e.to_string()))
    }

    fn axis(&self, axes: &Table, key: &str) -> Result<Axis> {
        let full = join("axes", key);
        let values = match axes.get(key) {
            None => return Err(self.error(&full, "missing")),
            Some(Value::Array(items)) => {
                if items.is_empty() {
                    return Err(self.error(&full, "empty list of values"));
                }
                items
                    .iter()
                    .enumerate()
                    .map(|(i, v)| self.number(v, &format!("{full}[{i}]")))
                    .collect::<Result<Vec<_>>>()?
            }
            Some(Value::Table(t)) => {
                self.only_keys(t, &full, &["start", "stop", "num", "spacing"])?;
                let log = match t.get("spacing") {
                    None => false,
                    Some(Value::String(m)) if m == "linear" => false,
                    Some(Value::String(m)) if m == "log" => true,
                    Some(v) => {
                        return Err(self.error(
                            &join(&full, "spacing"),
                            format!("{v} is not \"linear\" or \"log\""),
                        ))
                    }
                };
                let start = self.required_number(t, &full, "start")?;
                let stop = self.required_number(t, &full, "stop")?;
                let num = match t.get("num") {
                    Some(Value::Integer(n)) if *n >= 1 => *n as usize,
                    Some(Value::Integer(n)) => {
                        return Err(self.error(&join(&full, "num"), format!("{n} must be >= 1")))
                    }
                    Some(v) => {
                        return Err(self.error(
                            &join(&full, "num"),
                            format!("expected an integer, found {}", v.type_str()),
                        ))
                    }
                    None => return Err(self.error(&join(&full, "num"), "missing")),
                };
                if num > 1_000_000 {
                    return Err(self.error(&join(&full, "num"), format!("{num} is over 1000000")));
                }
                if stop < start {
                    return Err(self.error(
                        &full,
                        format!(
                            "inverted axis: stop {} is below start {}",
                            show(stop),
                            show(start)
                        ),
                    ));
                }
                if num > 1 && stop == start {
                    return Err(self.error(
                        &full,
                        format!(
                            "empty axis: start = stop = {} with num = {num}",
                            show(start)
                        ),
                    ));
                }
                if num == 1 && stop != start {
                    return Err(self.error(
                        &full,
                        "num = 1 needs start = stop (or give a list of values)",
                    ));
                }
                if log && start <= 0.0 {
                    return Err(self.error(
                        &join(&full, "start"),
                        format!("{} must be > 0 for log spacing", show(start)),
                    ));
                }
                if log {
                    Axis::logspace(start, stop, num)
                } else {
                    Axis::linspace(start, stop, num)
                }
            }
            Some(v) => {
                return Err(self.error(
                    &full,
                    format!(
                        "expected a list of values or {{ start, stop, num }}, found {}",
                        v.type_str()
                    ),
                ))
            }
        };
        // start/stop/num near the limits of a double can overflow to inf or NaN.
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(self.error(
                &full,
                format!("the axis overflows to {v}: keep start and stop well inside +-1e308"),
            ));
        }
        if let Some(i) = values.windows(2).position(|w| w[1] <= w[0]) {
            return Err(self.error(
                &full,
                format!(
                    "values must be strictly increasing ({} is followed by {})",
                    show(values[i]),
                    show(values[i + 1])
                ),
            ));
        }
        Ok(Axis { values })
    }
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

/// A parameter error from the library, told as a scene error at `key`.
fn parameter_error(reader: &Reader<'_>, key: &str, e: AtlasError) -> AtlasError {
    match e {
        AtlasError::InvalidParameter { value, reason, .. } => {
            reader.error(key, format!("{} {reason}", show(value)))
        }
        e => reader.error(key, e.to_string()),
    }
}

/// The text of a small input file (a scene, a profile's table), refused with the reason
/// where it is not a regular file (a folder, a device, a FIFO, which would be waited on) or
/// is above 1 MiB, far above any such file (a huge one is not read to the end); `what` says
/// what it should be, in the refusal.
pub fn read_small_text(path: &Path, what: &str) -> std::result::Result<String, String> {
    const MAX_BYTES: u64 = 1 << 20;
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err(format!("not a regular file ({what})"));
    }
    if meta.len() > MAX_BYTES {
        return Err(format!(
            "{} bytes: too large ({what}; at most {MAX_BYTES})",
            meta.len()
        ));
    }
    // (A byte-order mark, as some Windows editors write, is no part of the text: a profile
    // table's first row was refused as "\u{feff}0 -1".)
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

impl Scene {
    /// Reads and checks the scene file at `path`.
    pub fn from_file(path: &Path) -> Result<Scene> {
        let file = path.display().to_string();
        let text = read_small_text(path, "a scene is a TOML file").map_err(|reason| {
            AtlasError::Scene {
                file: file.clone(),
                key: "(file)".into(),
                reason,
            }
        })?;
        Scene::parse(&text, &file)
    }

    /// Parses and checks a scene's text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Scene> {
        let reader = Reader { file };
        let root: Table = text.parse().map_err(|e: toml::de::Error| {
            // The line, and its text (a number too large for TOML's integers named neither
            // the key nor the value).
            let line = match e.span() {
                Some(span) => {
                    let start = span.start.min(text.len());
                    let number = text[..start].matches('\n').count() + 1;
                    let content: String = text
                        .lines()
                        .nth(number - 1)
                        .unwrap_or_default()
                        .trim()
                        .chars()
                        .take(60)
                        .collect();
                    if content.is_empty() {
                        format!("line {number}")
                    } else {
                        format!("line {number} `{content}`")
                    }
                }
                None => "(syntax)".into(),
            };
            reader.error(&line, e.message().replace('\n', " "))
        })?;
        reader.only_keys(&root, "", &["name", "body", "axes", "solver", "outputs"])?;

        let name = match root.get("name") {
            Some(Value::String(s)) => s.clone(),
            Some(v) => {
                return Err(
                    reader.error("name", format!("expected a string, found {}", v.type_str()))
                )
            }
            None => return Err(reader.error("name", "missing")),
        };
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
            || name.starts_with('.')
        {
            return Err(reader.error(
                "name",
                format!(
                    "{name:?} must be non-empty, use only ASCII letters, digits, '-', '_' and \
                     '.', and not start with '.'"
                ),
            ));
        }

        let body = reader.table(&root, "", "body")?;
        reader.only_keys(body, "body", &["shape", "nu", "eta", "profile"])?;
        let shape = match body.get("shape") {
            None => None,
            Some(Value::String(name)) if name == "profile" => {
                Some(EdgedKind::Profile(reader.profile(body)?))
            }
            Some(Value::String(name)) => crate::body::shape_kind(name).ok_or_else(|| {
                reader.error(
                    "body.shape",
                    format!("unknown shape {name:?} (use {})", SHAPE_NAMES.join(", ")),
                )
            })?,
            Some(v) => {
                return Err(reader.error(
                    "body.shape",
                    format!("expected a string, found {}", v.type_str()),
                ))
            }
        };
        if body.contains_key("profile") && !matches!(shape, Some(EdgedKind::Profile(_))) {
            return Err(reader.error(
                "body.profile",
                format!(
                    "the shape {} takes no profile (only shape = \"profile\" does)",
                    shape_name(shape)
                ),
            ));
        }
        let nu = reader.required_number(body, "body", "nu")?;
        let eta = reader.required_number(body, "body", "eta")?;

        let axes = reader.table(&root, "", "axes")?;
        let second_name = second_parameter(shape);
        let plane_keys = ["kappa", "energy", "excess_energy", "lambda", "s"];
        let known: Vec<&str> = ["alpha"]
            .into_iter()
            .chain(second_name)
            .chain(plane_keys)
            .collect();
        if let Some(other) = ["beta", "cut"]
            .into_iter()
            .find(|k| axes.contains_key(*k) && Some(*k) != second_name)
        {
            let takes = match second_name {
                Some(name) => format!("alpha and {name}"),
                None => "alpha only".into(),
            };
            return Err(reader.error(
                &join("axes", other),
                format!(
                    "the shape {} has no parameter {other} (its axes are {takes})",
                    shape_name(shape)
                ),
            ));
        }
        reader.only_keys(axes, "axes", &known)?;
        let alpha = reader.axis(axes, "alpha")?;
        let second = match second_name {
            Some(name) => reader.axis(axes, name)?,
            None => Axis { values: vec![0.0] },
        };
        let has = |k: &str| axes.contains_key(k);
        let plane = match (
            has("kappa"),
            has("energy"),
            has("excess_energy"),
            has("lambda"),
            has("s"),
        ) {
            (true, true, false, false, false) => Plane::KappaEnergy,
            (true, false, true, false, false) => Plane::KappaExcess,
            (false, false, false, true, true) => Plane::Compact,
            _ => return Err(reader.error(
                "axes",
                "give the plane as kappa with energy, kappa with excess_energy, or lambda with s",
            )),
        };
        let [row_name, column_name] = plane.axis_names();
        let kappa = reader.axis(axes, row_name)?;
        let mut energy = reader.axis(axes, column_name)?;
        // κ and ε of every cell must be finite numbers whose squares do not overflow.
        // The value of largest size, with its sign (for the message), and that size.
        let widest = |a: &Axis| {
            a.values
                .iter()
                .copied()
                .fold(0.0f64, |m, v| if v.abs() > m.abs() { v } else { m })
        };
        let largest = |a: &Axis| widest(a).abs();
        let smallest_positive = |a: &Axis| {
            a.values
                .iter()
                .filter(|v| **v > 0.0)
                .fold(f64::INFINITY, |m, v| m.min(*v))
        };
        if plane != Plane::Compact && largest(&kappa) > MAX_KAPPA {
            return Err(reader.error(
                "axes.kappa",
                format!(
                    "{} is above {MAX_KAPPA:e} in size (kappa^2 would overflow)",
                    show(widest(&kappa))
                ),
            ));
        }
        // The smallest |κ| > 0 of a cell: κ itself (signed), or λ/s at the largest s.
        if plane == Plane::Compact {
            let (lambda, s) = (smallest_positive(&kappa), largest(&energy));
            if lambda.is_finite() && s > 0.0 && lambda / s < f64::MIN_POSITIVE {
                return Err(reader.error(
                    "axes.lambda",
                    format!(
                        "lambda = {} at s = {} gives kappa = lambda/s = {}, below 2.2e-308 \
                         (subnormal, or 0 by underflow): keep lambda/s at least 2.2250738585072014e-308",
                        show(lambda),
                        show(s),
                        show(lambda / s)
                    ),
                ));
            }
        } else if let Some(least) = kappa
            .values
            .iter()
            .filter(|v| **v != 0.0)
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .filter(|v| v.abs() < f64::MIN_POSITIVE)
        {
            return Err(reader.error(
                "axes.kappa",
                format!(
                    "a cell has kappa = {}, subnormal: give 0 or |kappa| >= 2.2250738585072014e-308",
                    show(*least)
                ),
            ));
        }
        if plane != Plane::Compact && largest(&energy) > MAX_ENERGY {
            return Err(reader.error(
                &format!("axes.{column_name}"),
                format!("{} is above {MAX_ENERGY:e} in size", show(widest(&energy))),
            ));
        }
        // On the excess plane ε = V_min(κ) + e, and V_min(κ) = κ²/2 + U at its minimum, O(1)
        // beside κ²/2 wherever ε nears 1e300: the cells' ε stays within the range every surface
        // takes (a wheel's scene at κ = 1e150, e = 1e300 ran its cells at ε = 1.5e300, which
        // `cells` refuses; adversary pass 32).
        if plane == Plane::KappaExcess {
            let top = energy
                .values
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            let half_square = 0.5 * largest(&kappa) * largest(&kappa);
            if top + half_square > MAX_ENERGY {
                return Err(reader.error(
                    "axes.excess_energy",
                    format!(
                        "{} at kappa = {} gives energy = V_min + excess_energy >= kappa^2/2 + excess_energy = {}, above {MAX_ENERGY:e}",
                        show(top),
                        show(widest(&kappa)),
                        show(top + half_square)
                    ),
                ));
            }
        }
        if plane == Plane::Compact {
            let s_min = smallest_positive(&energy);
            if s_min < MIN_S {
                return Err(reader.error(
                    "axes.s",
                    format!(
                        "{} is below {MIN_S:e}: energy = 1/s^2 must stay below 1e300 (s = 0 is the limit energy = infinity itself)",
                        show(s_min)
                    ),
                ));
            }
            if largest(&kappa) / s_min > MAX_KAPPA {
                return Err(reader.error(
                    "axes.lambda",
                    format!(
                        "lambda = {} at s = {} gives kappa = lambda/s = {}, above {MAX_KAPPA:e} (kappa^2 would overflow): keep lambda/s below it",
                        show(largest(&kappa)),
                        show(s_min),
                        show(largest(&kappa) / s_min)
                    ),
                ));
            }
            // −0 is 0: the limit column.
            for v in energy.values.iter_mut() {
                if *v == 0.0 {
                    *v = 0.0;
                }
            }
            if kappa.values[0] < 0.0 {
                return Err(reader.error(
                    "axes.lambda",
                    format!(
                        "{} must be >= 0 (lambda = kappa / sqrt(energy))",
                        show(kappa.values[0])
                    ),
                ));
            }
            if energy.values[0] < 0.0 {
                return Err(reader.error(
                    "axes.s",
                    format!(
                        "{} must be >= 0 (s = 1 / sqrt(energy))",
                        show(energy.values[0])
                    ),
                ));
            }
        }
        // Every body of the grid must be valid: each shape's parameters lie in intervals, so
        // checking the extremes of each axis is enough.
        for &a in &[alpha.values[0], *alpha.values.last().unwrap()] {
            for &b in &[second.values[0], *second.values.last().unwrap()] {
                if let Err(e) = AnyBody::new(shape, a, b, nu, eta) {
                    let key = match &e {
                        AtlasError::InvalidParameter { name, .. } => match *name {
                            "alpha" | "beta" | "cut" => format!("axes.{name}"),
                            other => format!("body.{other}"),
                        },
                        _ => "body".into(),
                    };
                    return Err(parameter_error(&reader, &key, e));
                }
            }
        }
        let mut options = CellOptions::default();
        if let Some(v) = root.get("solver") {
            let Value::Table(solver) = v else {
                return Err(reader.error(
                    "solver",
                    format!("expected a table, found {}", v.type_str()),
                ));
            };
            reader.only_keys(solver, "solver", &["tolerance", "method", "resonance_tol"])?;
            if solver.contains_key("tolerance") {
                options.tol = reader.required_number(solver, "solver", "tolerance")?;
            }
            if solver.contains_key("resonance_tol") {
                options.resonance_tol =
                    reader.required_number(solver, "solver", "resonance_tol")?;
            }
            match solver.get("method") {
                None => {}
                Some(Value::String(m)) if m == "quadrature" => options.method = Method::Quadrature,
                Some(Value::String(m)) if m == "ode" => options.method = Method::Ode,
                Some(v) => {
                    return Err(reader.error(
                        "solver.method",
                        format!("{v} is not \"quadrature\" or \"ode\""),
                    ))
                }
            }
            if let Err(e) = options.validate() {
                let key = match &e {
                    AtlasError::InvalidParameter { name: "tol", .. } => "solver.tolerance",
                    _ => "solver.resonance_tol",
                };
                return Err(parameter_error(&reader, key, e));
            }
        }

        let mut fields: Vec<Field> = Field::ALL.to_vec();
        let mut layout = Layout::default();
        if let Some(v) = root.get("outputs") {
            let Value::Table(outputs) = v else {
                return Err(reader.error(
                    "outputs",
                    format!("expected a table, found {}", v.type_str()),
                ));
            };
            reader.only_keys(outputs, "outputs", &["fields", "layout"])?;
            match outputs.get("layout") {
                None => {}
                Some(Value::String(name)) => {
                    layout = Layout::from_name(name).ok_or_else(|| {
                        reader.error(
                            "outputs.layout",
                            format!("unknown layout {name:?} (use {})", Layout::NAMES),
                        )
                    })?;
                }
                Some(v) => {
                    return Err(reader.error(
                        "outputs.layout",
                        format!("expected a string, found {}", v.type_str()),
                    ))
                }
            }
            match outputs.get("fields") {
                None => {}
                Some(Value::Array(items)) => {
                    if items.is_empty() {
                        return Err(reader.error("outputs.fields", "empty list"));
                    }
                    fields.clear();
                    for (i, item) in items.iter().enumerate() {
                        let key = format!("outputs.fields[{i}]");
                        let Value::String(s) = item else {
                            return Err(reader.error(
                                &key,
                                format!("expected a string, found {}", item.type_str()),
                            ));
                        };
                        let field = Field::from_name(s).ok_or_else(|| {
                            let names: Vec<&str> = Field::ALL.iter().map(|f| f.name()).collect();
                            reader.error(
                                &key,
                                format!("unknown field {s:?} (known: {})", names.join(", ")),
                            )
                        })?;
                        if fields.contains(&field) {
                            return Err(reader.error(&key, format!("{s:?} is listed twice")));
                        }
                        fields.push(field);
                    }
                    if !fields.contains(&Field::Status) {
                        fields.push(Field::Status);
                    }
                    fields.sort();
                }
                Some(v) => {
                    return Err(reader.error(
                        "outputs.fields",
                        format!("expected a list of strings, found {}", v.type_str()),
                    ))
                }
            }
        }
        options.drift = fields.iter().any(|f| f.needs_drift());
        // The options against the body (the ODE method needs a body without edges).
        let body = AnyBody::new(shape, alpha.values[0], second.values[0], nu, eta)?;
        crate::with_body!(&body, b => options.check_for(b))
            .map_err(|e| reader.error("solver.method", format!("{e} ({})", shape_name(shape))))?;

        Ok(Scene {
            name,
            shape,
            nu,
            eta,
            alpha,
            second,
            kappa,
            energy,
            plane,
            options,
            fields,
            layout,
            text: text.to_string(),
        })
    }

    /// The shape of the grid: (n_α, n of the second parameter, n_κ, n_ε).
    pub fn shape(&self) -> [usize; 4] {
        [
            self.alpha.len(),
            self.second.len(),
            self.kappa.len(),
            self.energy.len(),
        ]
    }

    /// The number of cells of the grid.
    pub fn cells(&self) -> usize {
        self.shape().iter().product()
    }

    /// The body at grid point (i_α, i of the second parameter).
    pub fn body(&self, ia: usize, ib: usize) -> AnyBody {
        AnyBody::new(
            self.shape,
            self.alpha.values[ia],
            self.second.values[ib],
            self.nu,
            self.eta,
        )
        .expect("the scene's bodies were checked when it was parsed")
    }

    /// The shape's name: `ellipsoid`, `disk`, `truncated_ball` or `wheel`.
    pub fn shape_name(&self) -> &'static str {
        shape_name(self.shape)
    }

    /// The name of the second grid axis and file dimension ([`Scene::second`]): `beta`,
    /// `cut`, or None for the disk (its file has no such dimension).
    pub fn second_name(&self) -> Option<&'static str> {
        second_parameter(self.shape)
    }

    /// A 64-bit fingerprint of the scene's text and of the program (version and git commit):
    /// resume and merge only continue work of the same scene computed by the same program, so
    /// that a file never mixes values from two versions of the solver.
    pub fn fingerprint(&self) -> u64 {
        let mut hash = fnv1a(0xcbf2_9ce4_8422_2325, self.text.as_bytes());
        hash = fnv1a(hash, env!("CARGO_PKG_VERSION").as_bytes());
        fnv1a(hash, env!("RUBBER_ATLAS_GIT_COMMIT").as_bytes())
    }
}

/// FNV-1a over `bytes`, continuing from `hash`.
pub fn fnv1a(mut hash: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}
