//! The extension module `rubber_atlas._core` of the Python package (feature `python`, built
//! by maturin without the `hdf5` feature, so that the only HDF5 in a Python process is
//! h5py's). Thin: it converts arguments, releases the GIL around the library's work, and
//! hands back flat numpy arrays and table columns with their CF metadata; the package's
//! Python code shapes them into xarray objects.

use crate::atlas::{self, CellPoint, Column, Kind, COMPONENT_SLOTS};
use crate::cell::{CellOptions, Method};
use crate::critical::CriticalSet;
use crate::error::AtlasError;
use crate::family::{ComponentAxis, Layout};
use crate::resonance::{trace_curves_until, ResonanceOptions};
use crate::scene::Field;
use crate::table::{Table, Values};
use crate::trajectory::{Duration, Model, Request, StartAt};
use crate::verdict::{self, VerdictOptions};
use crate::{AnyBody, EllipsoidBody};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// How often a running computation looks for Ctrl-C.
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(20);

fn value_error(e: AtlasError) -> PyErr {
    // (In the words of the package's keywords, not the command's flags.)
    PyValueError::new_err(
        e.to_string()
            .replace("beta-min", "beta_min")
            .replace("beta-max", "beta_max")
            .replace("kappa-max", "kappa_max"),
    )
}

/// A trajectory error in the words of `ra.trajectory`'s keywords, not the command's flags.
fn trajectory_error(e: AtlasError) -> PyErr {
    // A computation that failed (the command's exit 1), not a bad input.
    let failed = matches!(
        e,
        AtlasError::Integration { .. } | AtlasError::Unresolved { .. }
    );
    let text = e
        .to_string()
        .replace("give --t-end", "give t_end=")
        .replace("t-end", "t_end")
        .replace("theta-dot0", "theta_dot0")
        .replace("--allow-large", "allow_large=True");
    if failed {
        PyRuntimeError::new_err(text)
    } else {
        PyValueError::new_err(text)
    }
}

fn bad(message: String) -> PyErr {
    PyValueError::new_err(message)
}

/// The fields named by `names` (all of them for None).
/// As a scene's `[outputs] fields`: known names, none twice, not empty, and `status`
/// always (without it a failed or unconverged value would not be flagged).
fn parse_fields(names: Option<Vec<String>>) -> PyResult<Vec<Field>> {
    let Some(names) = names else {
        return Ok(Field::ALL.to_vec());
    };
    if names.is_empty() {
        return Err(bad(
            "fields is empty: name at least one field, or leave it out for all".into(),
        ));
    }
    let mut fields = Vec::with_capacity(names.len() + 1);
    for n in &names {
        let field = Field::from_name(n).ok_or_else(|| {
            bad(format!(
                "unknown field {n:?}; known: {}",
                Field::ALL.map(|f| f.name()).join(", ")
            ))
        })?;
        if fields.contains(&field) {
            return Err(bad(format!("field {n:?} is listed twice")));
        }
        fields.push(field);
    }
    if !fields.contains(&Field::Status) {
        fields.push(Field::Status);
    }
    fields.sort();
    Ok(fields)
}

/// A count given from Python (`samples`, `component`, …), refused below `min` naming it.
fn count(name: &str, value: i64, min: i64) -> PyResult<usize> {
    if value < min {
        return Err(bad(format!("invalid {name} = {value}: must be >= {min}")));
    }
    usize::try_from(value).map_err(|_| bad(format!("invalid {name} = {value}: too large")))
}

/// `resolution` of a verdict (from `lowest`) or of the boundaries, refused naming its range.
fn resolution_between(value: i64, lowest: i64, what: &str) -> PyResult<usize> {
    if !(lowest..=4096).contains(&value) {
        return Err(bad(format!(
            "invalid resolution = {value}: must be between {lowest} and 4096{what}"
        )));
    }
    Ok(value as usize)
}

/// The pool of `threads` threads, capped at the machine's cores as the command line caps
/// them (None: rayon's global pool, which honours RAYON_NUM_THREADS).
fn pool(threads: Option<i64>) -> PyResult<Option<rayon::ThreadPool>> {
    let Some(n) = threads else {
        // (rayon's pool ignores a RAYON_NUM_THREADS that is not a number; the program refuses
        // it, and so does the package: adversary pass 34.)
        crate::machine::threads_from_env().map_err(value_error)?;
        return Ok(None);
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let n = count("threads", n, 1)?.min(cores);
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map(Some)
        .map_err(|e| bad(e.to_string()))
}

/// Runs `work` on `pool` (or rayon's global pool) with the GIL released.
fn in_pool<T: Send>(
    py: Python<'_>,
    pool: &Option<rayon::ThreadPool>,
    work: impl FnOnce() -> T + Send,
) -> T {
    match pool {
        Some(pool) => py.detach(|| pool.install(work)),
        None => py.detach(work),
    }
}

/// Sets its flag when dropped: a worker's "done", also when it panics.
struct SetOnDrop<'a>(&'a std::sync::atomic::AtomicBool);

impl Drop for SetOnDrop<'_> {
    fn drop(&mut self) {
        self.0.store(true, std::sync::atomic::Ordering::Release);
    }
}

/// Runs `work` on `pool` (or rayon's global pool) with the GIL released, looking for Ctrl-C
/// every [`SIGNAL_POLL`] meanwhile. On one, the `stop` that `work` is given says so; `work`
/// polls it between cells (or a verdict's components) and returns early, and the
/// KeyboardInterrupt is raised then: the latency is one cell's (or component's) time.
fn interruptible<T: Send>(
    py: Python<'_>,
    pool: &Option<rayon::ThreadPool>,
    work: impl FnOnce(&(dyn Fn() -> bool + Sync)) -> T + Send,
) -> PyResult<T> {
    use std::sync::atomic::{AtomicBool, Ordering};
    if pool.is_none() {
        crate::machine::threads_from_env().map_err(value_error)?;
    }
    let stop = AtomicBool::new(false);
    let done = AtomicBool::new(false);
    let asked_to_stop = || stop.load(Ordering::Relaxed);
    std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let _done = SetOnDrop(&done);
            match pool {
                Some(pool) => pool.install(|| work(&asked_to_stop)),
                None => work(&asked_to_stop),
            }
        });
        let mut interrupt = None;
        while !done.load(Ordering::Acquire) {
            py.detach(|| {
                let start = std::time::Instant::now();
                while !done.load(Ordering::Acquire) && start.elapsed() < SIGNAL_POLL {
                    std::thread::sleep(std::time::Duration::from_millis(1));
                }
            });
            if interrupt.is_none() {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::Relaxed);
                    interrupt = Some(e);
                }
            }
        }
        let out = worker
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        interrupt.map_or(Ok(out), Err)
    })
}

/// Refuses a request of about `bytes` of memory that the machine cannot hold, unless
/// `allow_large`.
fn check_memory(bytes: f64, allow_large: bool, remedy: &str) -> PyResult<()> {
    crate::machine::check_memory(bytes, allow_large, remedy).map_err(value_error)
}

/// What is short when a call of the package needs `bytes` of memory, by the core's rule
/// ([`crate::machine::memory_short`]): "about X of memory (Y available)", or None.
#[pyfunction]
fn memory_short(bytes: f64) -> Option<String> {
    crate::machine::memory_short(bytes)
}

/// The metadata of the variables of `fields`, in file order: name, whether it has a value
/// per component, dtype, long_name, units, comment, flag_values and flag_meanings.
#[pyfunction]
#[pyo3(signature = (fields=None))]
fn variables(py: Python<'_>, fields: Option<Vec<String>>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for v in atlas::variables(&parse_fields(fields)?) {
        let d = PyDict::new(py);
        d.set_item("name", v.name)?;
        d.set_item("per_component", !v.kind.per_cell())?;
        d.set_item(
            "dtype",
            match v.kind {
                Kind::Value | Kind::CellValue => "float64",
                Kind::Flag | Kind::CellFlag => "uint8",
            },
        )?;
        d.set_item("long_name", v.long_name)?;
        d.set_item("units", v.units.units)?;
        d.set_item("comment", v.units.comment)?;
        if let Some((values, meanings)) = v.flag_attributes() {
            d.set_item("flag_values", values)?;
            d.set_item("flag_meanings", meanings)?;
        }
        list.append(d)?;
    }
    Ok(list)
}

/// The arrays' values, refused in one line (naming them as `names`) unless they have one
/// length.
fn equal_length<'a>(
    arrays: &[&'a PyReadonlyArray1<'_, f64>],
    names: &str,
) -> PyResult<Vec<&'a [f64]>> {
    let slices = arrays
        .iter()
        .map(|a| a.as_slice().map_err(|e| bad(e.to_string())))
        .collect::<PyResult<Vec<&[f64]>>>()?;
    if slices.iter().any(|s| s.len() != slices[0].len()) {
        return Err(bad(format!("{names} must have one length")));
    }
    Ok(slices)
}

/// Cell `i` of the arrays α, β, ν, η, κ and, if given, ε (else ε = 0).
fn point(slices: &[&[f64]], i: usize) -> CellPoint {
    CellPoint {
        alpha: slices[0][i],
        beta: slices[1][i],
        nu: slices[2][i],
        eta: slices[3][i],
        kappa: slices[4][i],
        energy: slices.get(5).map_or(0.0, |e| e[i]),
    }
}

/// Solves cells given by six equal-length arrays, in parallel with the GIL released. Returns
/// a dict: `columns`, the values of every variable of `fields` as (name, flat array) pairs
/// in file order (a per-component variable has one value per cell and component slot, slot
/// fastest); `component`, the labels of the slots (the families present, or the ranks in
/// θ_min up to the most components of a cell: no slot is empty in every cell); `layout`.
#[pyfunction]
#[pyo3(signature = (alpha, beta, nu, eta, kappa, energy, tol, method, resonance_tol, fields=None, threads=None, allow_large=false, layout="family", shape="ellipsoid", profile=None))]
#[allow(clippy::too_many_arguments)]
fn cells<'py>(
    py: Python<'py>,
    alpha: PyReadonlyArray1<'py, f64>,
    beta: PyReadonlyArray1<'py, f64>,
    nu: PyReadonlyArray1<'py, f64>,
    eta: PyReadonlyArray1<'py, f64>,
    kappa: PyReadonlyArray1<'py, f64>,
    energy: PyReadonlyArray1<'py, f64>,
    tol: f64,
    method: &str,
    resonance_tol: f64,
    fields: Option<Vec<String>>,
    threads: Option<i64>,
    allow_large: bool,
    layout: &str,
    shape: &str,
    profile: Option<Vec<Vec<f64>>>,
) -> PyResult<Bound<'py, PyDict>> {
    let kind = shape_kind(shape, profile.as_deref())?;
    let layout = Layout::from_name(layout)
        .ok_or_else(|| bad(format!("layout {layout:?}: use {}", Layout::NAMES)))?;
    let slices = equal_length(
        &[&alpha, &beta, &nu, &eta, &kappa, &energy],
        "alpha, beta, nu, eta, kappa and energy",
    )?;
    let n = slices[0].len();
    let fields = parse_fields(fields)?;
    let vars = atlas::variables(&fields);
    // The points, the blocks and their concatenation: about twice the output per cell.
    // Room for every slot of the layout while computing; the empty ones are dropped after.
    // (An edged body's θ_min slots are counted below, as `run`'s census counts them, and
    // the memory checked again for them.)
    let mut room = ComponentAxis::full(
        layout,
        crate::family::Family::possible_for(kind.as_ref()),
        COMPONENT_SLOTS,
    );
    let check_room = |room: &ComponentAxis| {
        let per_cell: usize = vars.iter().map(|v| v.kind.bytes_per_cell(room.len())).sum();
        check_memory(
            n as f64 * (std::mem::size_of::<CellPoint>() + 2 * per_cell) as f64,
            allow_large,
            "give fewer cells at a time, or allow_large=True",
        )
    };
    check_room(&room)?;
    let pool = pool(threads)?;
    let points: Vec<CellPoint> = (0..n).map(|i| point(&slices, i)).collect();
    let options = CellOptions {
        tol,
        method: match method {
            "quadrature" => Method::Quadrature,
            "ode" => Method::Ode,
            other => {
                return Err(bad(format!(
                    "method {other:?}: use \"quadrature\" or \"ode\""
                )))
            }
        },
        drift: fields.iter().any(|f| f.needs_drift()),
        resonance_tol,
    };
    options.validate().map_err(value_error)?;
    // Ctrl-C (KeyboardInterrupt) is heard within a cell's time.
    let block = match kind {
        None => {
            let bodies = atlas::cell_bodies(&points).map_err(value_error)?;
            solve_cells(py, &pool, &points, &bodies, &vars, &room, &options)?
        }
        Some(crate::EdgedKind::Profile(profile)) => {
            let bodies = profile_bodies(&points, profile)?;
            room = counted_room(py, &pool, &points, &bodies, room)?;
            check_room(&room)?;
            solve_cells(py, &pool, &points, &bodies, &vars, &room, &options)?
        }
        Some(kind) => {
            let bodies = edged_bodies(&points, kind)?;
            room = counted_room(py, &pool, &points, &bodies, room)?;
            check_room(&room)?;
            solve_cells(py, &pool, &points, &bodies, &vars, &room, &options)?
        }
    };
    // The slots some cell holds.
    let family = block
        .flags(&vars, "family")
        .expect("family is always written");
    let used: Vec<usize> = (0..room.len())
        .filter(|&k| {
            family
                .iter()
                .skip(k)
                .step_by(room.len())
                .any(|&f| f != atlas::FLAG_FILL)
        })
        .collect();
    let axis = if used.is_empty() {
        // No motion anywhere: one empty slot, as in a file.
        ComponentAxis::of(layout, &Default::default())
    } else {
        ComponentAxis {
            layout,
            labels: used.iter().map(|&k| room.labels[k]).collect(),
        }
    };
    let block = block.select_slots(&vars, if used.is_empty() { &[0] } else { &used });
    let list = PyList::empty(py);
    for (v, column) in vars.iter().zip(block.columns) {
        let array = match column {
            Column::F64(x) => PyArray1::from_vec(py, x).into_any(),
            Column::U8(x) => PyArray1::from_vec(py, x).into_any(),
        };
        list.append((v.name, array))?;
    }
    let out = PyDict::new(py);
    out.set_item("columns", list)?;
    out.set_item("component", axis.labels.clone())?;
    out.set_item("layout", layout.name())?;
    if let Some((values, meanings)) = axis.flag_attributes() {
        out.set_item("flag_values", values)?;
        out.set_item("flag_meanings", meanings)?;
    }
    Ok(out)
}

/// The shape named `name`: None for the ellipsoid, else the edged kind, or the profile of
/// `profile`'s rows (which only the shape "profile" takes, and needs).
fn shape_kind(name: &str, profile: Option<&[Vec<f64>]>) -> PyResult<Option<crate::EdgedKind>> {
    match (name, profile) {
        ("profile", Some(rows)) => {
            return crate::Profile::from_points(rows)
                .map(|p| Some(crate::EdgedKind::Profile(p)))
                .map_err(value_error)
        }
        ("profile", None) => {
            return Err(bad(
                "shape \"profile\" needs profile=, the meridian's points as rows (rho, z) or (rho, z, edge)"
                    .into(),
            ))
        }
        (_, Some(_)) => {
            return Err(bad(format!(
                "shape {name:?} takes no profile (only shape=\"profile\" does)"
            )))
        }
        _ => {}
    }
    crate::body::shape_kind(name).ok_or_else(|| {
        let names: Vec<String> = crate::body::SHAPE_NAMES
            .iter()
            .map(|n| format!("{n:?}"))
            .collect();
        bad(format!(
            "shape {name:?}: use {} or {}",
            names[..names.len() - 1].join(", "),
            names[names.len() - 1]
        ))
    })
}

/// The body of `shape` (`ellipsoid`, or an edged one whose cut is given in `beta`).
fn any_body(
    shape: &str,
    profile: Option<&[Vec<f64>]>,
    alpha: f64,
    beta: f64,
    nu: f64,
    eta: f64,
) -> PyResult<AnyBody> {
    AnyBody::new(shape_kind(shape, profile)?, alpha, beta, nu, eta).map_err(value_error)
}

/// The bodies of `points` of one profile (α varies).
fn profile_bodies(
    points: &[CellPoint],
    profile: &'static crate::Profile,
) -> PyResult<Vec<crate::Body<crate::ProfileShape>>> {
    atlas::bodies_of(points, |p| {
        crate::Body::new(crate::ProfileShape::new(profile, p.alpha)?, p.nu, p.eta)
    })
    .map_err(value_error)
}

/// The edged bodies of `points`, each with its cut in `beta` (ignored by the disk).
fn edged_bodies(
    points: &[CellPoint],
    kind: crate::EdgedKind,
) -> PyResult<Vec<crate::Body<crate::EdgedShape>>> {
    atlas::bodies_of(points, |p| {
        crate::Body::new(crate::EdgedShape::of(kind, p.alpha, p.beta)?, p.nu, p.eta)
    })
    .map_err(value_error)
}

/// The θ_min layout's room for cells of edged `bodies`, whose wells are not known in advance:
/// as many slots as the most components of one cell, counted as `run`'s census counts them
/// (a symmetric barrel's κ = 0 cells have four, where the ellipsoid's room is three). The
/// family layout's room, every family, is kept.
fn counted_room<S: crate::Shape>(
    py: Python<'_>,
    pool: &Option<rayon::ThreadPool>,
    points: &[CellPoint],
    bodies: &[crate::Body<S>],
    room: ComponentAxis,
) -> PyResult<ComponentAxis> {
    if room.layout != Layout::ThetaMin {
        return Ok(room);
    }
    let most = interruptible(py, pool, |stop| {
        atlas::most_components(points, bodies, stop)
    })?;
    Ok(ComponentAxis::full(Layout::ThetaMin, &[], most.max(1)))
}

/// [`atlas::compute_cells`] of `bodies` with the GIL released, stopped by Ctrl-C; the options
/// are checked against the bodies first (the ODE method needs a body without kinks).
fn solve_cells<S: crate::Shape>(
    py: Python<'_>,
    pool: &Option<rayon::ThreadPool>,
    points: &[CellPoint],
    bodies: &[crate::Body<S>],
    vars: &[atlas::Variable],
    room: &ComponentAxis,
    options: &CellOptions,
) -> PyResult<atlas::Block> {
    if let Some(body) = bodies.first() {
        options.check_for(body).map_err(value_error)?;
    }
    interruptible(py, pool, |stop| {
        atlas::compute_cells(points, bodies, vars, room, options, stop)
    })
}

/// The bottom of V (its deepest minimum) at each (α, β, ν, η, κ) of five equal-length
/// arrays, in parallel with the GIL released: the origin of the `excess_energy` axis, as an
/// atlas's `kappa`/`excess_energy` plane measures it. A bad cell is refused, naming its index.
#[pyfunction]
#[pyo3(signature = (alpha, beta, nu, eta, kappa, threads=None, shape="ellipsoid", profile=None))]
#[allow(clippy::too_many_arguments)]
fn bottoms<'py>(
    py: Python<'py>,
    alpha: PyReadonlyArray1<'py, f64>,
    beta: PyReadonlyArray1<'py, f64>,
    nu: PyReadonlyArray1<'py, f64>,
    eta: PyReadonlyArray1<'py, f64>,
    kappa: PyReadonlyArray1<'py, f64>,
    threads: Option<i64>,
    shape: &str,
    profile: Option<Vec<Vec<f64>>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let kind = shape_kind(shape, profile.as_deref())?;
    let slices = equal_length(
        &[&alpha, &beta, &nu, &eta, &kappa],
        "alpha, beta, nu, eta and kappa",
    )?;
    let points: Vec<CellPoint> = (0..slices[0].len()).map(|i| point(&slices, i)).collect();
    let pool = pool(threads)?;
    let values = match kind {
        None => {
            let bodies = atlas::cell_bodies(&points).map_err(value_error)?;
            in_pool(py, &pool, || lowest_minima(&points, &bodies))
        }
        Some(crate::EdgedKind::Profile(profile)) => {
            let bodies = profile_bodies(&points, profile)?;
            in_pool(py, &pool, || lowest_minima(&points, &bodies))
        }
        Some(kind) => {
            let bodies = edged_bodies(&points, kind)?;
            in_pool(py, &pool, || lowest_minima(&points, &bodies))
        }
    };
    Ok(PyArray1::from_vec(py, values))
}

/// The lowest minimum of V at each point's κ (NaN where V has none).
fn lowest_minima<S: crate::Shape>(points: &[CellPoint], bodies: &[crate::Body<S>]) -> Vec<f64> {
    use rayon::prelude::*;
    points
        .par_iter()
        .zip(bodies)
        .map(|(p, body)| {
            crate::torus::EffectivePotential::new(body, p.kappa)
                .lowest_minimum()
                .unwrap_or(f64::NAN)
        })
        .collect()
}

/// A table as a dict: `dimension`, `columns` (dicts of name, values, long_name, units,
/// comment, flag_values, flag_meanings) and `attributes`.
fn table_dict<'py>(py: Python<'py>, table: Table) -> PyResult<Bound<'py, PyDict>> {
    let columns = PyList::empty(py);
    for c in table.columns {
        let d = PyDict::new(py);
        d.set_item("name", c.name)?;
        let values = match c.values {
            Values::F64(x) => PyArray1::from_vec(py, x).into_any(),
            Values::I32(x) => PyArray1::from_vec(py, x).into_any(),
            Values::U8(x) => PyArray1::from_vec(py, x).into_any(),
        };
        d.set_item("values", values)?;
        d.set_item("long_name", c.long_name)?;
        d.set_item("units", c.units.units)?;
        d.set_item("comment", c.units.comment)?;
        if let Some((values, meanings)) = c.flags {
            d.set_item("flag_values", values.to_vec())?;
            d.set_item("flag_meanings", meanings)?;
        }
        columns.append(d)?;
    }
    let attributes = PyDict::new(py);
    for (k, v) in table.attributes {
        match v {
            crate::cf::AttrValue::Text(t) => attributes.set_item(k, t)?,
            crate::cf::AttrValue::Number(x) => attributes.set_item(k, x)?,
            crate::cf::AttrValue::Integer(i) => attributes.set_item(k, i)?,
        }
    }
    let d = PyDict::new(py);
    d.set_item("dimension", table.dimension)?;
    d.set_item("columns", columns)?;
    d.set_item("attributes", attributes)?;
    Ok(d)
}

/// The critical set of one body (paper §4): its fixed-point curves as a table, and its
/// summary as JSON.
#[pyfunction]
#[pyo3(signature = (alpha, beta, nu, eta, samples, kappa_max, allow_large=false, shape="ellipsoid", profile=None))]
#[allow(clippy::too_many_arguments)]
fn diagram<'py>(
    py: Python<'py>,
    alpha: f64,
    beta: f64,
    nu: f64,
    eta: f64,
    samples: i64,
    kappa_max: f64,
    allow_large: bool,
    shape: &str,
    profile: Option<Vec<Vec<f64>>>,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let samples = count("samples", samples, 1)?;
    // As the command measured it: 245 bytes per sample at the peak.
    check_memory(
        300.0 * samples as f64,
        allow_large,
        "use fewer samples, or allow_large=True",
    )?;
    let body = any_body(shape, profile.as_deref(), alpha, beta, nu, eta)?;
    // Ctrl-C is heard every 65,536 samples (it used to wait for the whole set, and a
    // KeyboardInterrupt pending at the first NumPy call became a panic).
    let set = interruptible(py, &None, |stop| {
        CriticalSet::of_any(&body, samples, kappa_max, stop)
    })?
    .map_err(value_error)?;
    let summary = serde_json::to_string(&set).map_err(|e| bad(e.to_string()))?;
    // (Gathering the table's columns takes seconds at 5e7 samples: heard between columns.)
    let table = interruptible(py, &None, |stop| crate::table::diagram_until(&set, stop))?
        .ok_or_else(|| bad("interrupted".into()))?;
    Ok((table_dict(py, table)?, summary))
}

/// A trajectory (the reduced model or the full one) as a table along `t`, with its start
/// (κ, ε, θ(0), θ̇(0)).
#[pyfunction]
#[pyo3(signature = (alpha, beta, nu, eta, kappa, energy, component, theta0, theta_dot0, periods, t_end, samples, model, tol, allow_large=false, shape="ellipsoid", profile=None))]
#[allow(clippy::too_many_arguments)]
fn trajectory<'py>(
    py: Python<'py>,
    alpha: f64,
    beta: f64,
    nu: f64,
    eta: f64,
    kappa: f64,
    energy: Option<f64>,
    component: i64,
    theta0: Option<f64>,
    theta_dot0: f64,
    periods: Option<f64>,
    t_end: Option<f64>,
    samples: i64,
    model: &str,
    tol: f64,
    allow_large: bool,
    shape: &str,
    profile: Option<Vec<Vec<f64>>>,
) -> PyResult<(Bound<'py, PyDict>, [f64; 5])> {
    let component = count("component", component, 0)?;
    let samples = count("samples", samples, 1)?;
    check_memory(
        crate::trajectory::MEMORY_PER_SAMPLE * samples as f64,
        allow_large,
        "use fewer samples, or allow_large=True",
    )?;
    let body = any_body(shape, profile.as_deref(), alpha, beta, nu, eta)?;
    let start = match (energy, theta0) {
        (Some(energy), None) => StartAt::Energy { energy, component },
        (None, Some(theta0)) => StartAt::Angle { theta0, theta_dot0 },
        _ => return Err(bad("give exactly one of energy= and theta0=".into())),
    };
    let duration = match (periods, t_end) {
        (Some(k), None) => Duration::Periods(k),
        (None, Some(t)) => Duration::Until(t),
        _ => return Err(bad("give exactly one of periods= and t_end=".into())),
    };
    let model = match model {
        "reduced" => Model::Reduced,
        "full" => Model::Full,
        other => return Err(bad(format!("model {other:?}: use \"reduced\" or \"full\""))),
    };
    let request = Request {
        kappa,
        start,
        duration,
        samples,
        model,
        tol,
        step_budget: (!allow_large).then_some(crate::trajectory::STEP_BUDGET),
    };
    // Ctrl-C is heard between integrator runs (at most 100,000 steps each).
    let (start, traj, energy) = interruptible(py, &None, |stop| {
        crate::with_body!(&body, b => request
            .run_until(b, stop)
            .map(|(start, traj)| (start, traj, start.energy(b))))
    })?
    .map_err(trajectory_error)?;
    let start = [
        start.kappa,
        energy,
        start.theta0,
        start.theta_dot0,
        traj.energy_drift,
    ];
    Ok((table_dict(py, crate::table::trajectory(&traj))?, start))
}

/// The resonance curves N = `rotation_number` in a window of the (κ, ε) plane, as a table
/// along `sample`, and the window's smallest energy.
#[pyfunction]
#[pyo3(signature = (alpha, beta, nu, eta, rotation_number, kappa_min, kappa_max, energy_min, energy_max, grid, tol, shape="ellipsoid", profile=None))]
#[allow(clippy::too_many_arguments)]
fn resonance<'py>(
    py: Python<'py>,
    alpha: f64,
    beta: f64,
    nu: f64,
    eta: f64,
    rotation_number: f64,
    kappa_min: f64,
    kappa_max: f64,
    energy_min: Option<f64>,
    energy_max: f64,
    grid: i64,
    tol: f64,
    shape: &str,
    profile: Option<Vec<Vec<f64>>>,
) -> PyResult<(Bound<'py, PyDict>, f64)> {
    // (The whole range where a count below it is refused: "must be >= 1" for -1 named
    // only half of it; adversary pass of 2026-11-28.)
    if grid < 4 {
        return Err(bad(format!(
            "invalid grid = {grid}: {}",
            crate::resonance::GRID_RANGE
        )));
    }
    let grid = count("grid", grid, 4)?;
    let body = any_body(shape, profile.as_deref(), alpha, beta, nu, eta)?;
    let options = crate::with_body!(&body, b => ResonanceOptions::window(
        b,
        rotation_number,
        (kappa_min, kappa_max),
        energy_min,
        energy_max,
        grid,
        tol,
    ));
    // Ctrl-C is heard between seed rows and continuation steps.
    let curves = interruptible(
        py,
        &None,
        |stop| crate::with_body!(&body, b => trace_curves_until(b, &options, stop)),
    )?
    .map_err(value_error)?;
    Ok((
        table_dict(py, crate::table::resonance(&curves))?,
        options.energy.0,
    ))
}

/// Which integers N reaches over the (κ, ε) plane of one body of any shape, as JSON (the
/// `verdict --shape … --json` object), with the GIL released and Ctrl-C heard between
/// components.
#[pyfunction]
#[pyo3(signature = (alpha, beta, nu, eta, tol, resolution, shape="ellipsoid", profile=None))]
#[allow(clippy::too_many_arguments)]
fn census(
    py: Python<'_>,
    alpha: f64,
    beta: f64,
    nu: f64,
    eta: f64,
    tol: f64,
    resolution: i64,
    shape: &str,
    profile: Option<Vec<Vec<f64>>>,
) -> PyResult<String> {
    let resolution = resolution_between(resolution, 8, "")?;
    let body = any_body(shape, profile.as_deref(), alpha, beta, nu, eta)?;
    let options = crate::verdict::CensusOptions { tol, resolution };
    let report = interruptible(py, &None, |stop| {
        crate::verdict::census_report(&body, &options, stop)
    })?
    .map_err(value_error)?;
    serde_json::to_string(&report).map_err(|e| bad(e.to_string()))
}

/// The verdict of the boundedness hypothesis (docs/hypothesis.md) for each body, as JSON (the
/// `verdict --json` object), computed in parallel with the GIL released.
#[pyfunction]
#[pyo3(signature = (alpha, beta, nu, eta, tol, resolution, threads=None, allow_large=false))]
#[allow(clippy::too_many_arguments)]
fn verdicts(
    py: Python<'_>,
    alpha: Vec<f64>,
    beta: Vec<f64>,
    nu: Vec<f64>,
    eta: Vec<f64>,
    tol: f64,
    resolution: i64,
    threads: Option<i64>,
    allow_large: bool,
) -> PyResult<Vec<String>> {
    use rayon::prelude::*;
    let resolution = resolution_between(resolution, 8, "")?;
    let pool = pool(threads)?;
    let n = alpha.len();
    if [beta.len(), nu.len(), eta.len()].iter().any(|&m| m != n) {
        return Err(bad("alpha, beta, nu and eta must have one length".into()));
    }
    // A bad body is named by its position, as `cells` names a bad cell, before any is
    // computed (an α < 0 was refused, with no position, after the others' verdicts:
    // adversary pass 38).
    let bodies = (0..n)
        .map(|i| {
            verdict::check_alpha(alpha[i])
                .and_then(|()| EllipsoidBody::ellipsoid(alpha[i], beta[i], nu[i], eta[i]))
                .map_err(|e| {
                    value_error(AtlasError::Atlas {
                        path: format!("cell {i}"),
                        reason: e.to_string(),
                    })
                })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let options = VerdictOptions {
        tol,
        resolution,
        counterexamples: true,
        coarse_first: true,
    };
    // As many bodies are sampled at once as the pool has threads: each one's samples (the
    // verdict checks one body's alone).
    let at_once = pool
        .as_ref()
        .map_or_else(rayon::current_num_threads, |p| p.current_num_threads())
        .min(n);
    check_memory(
        at_once as f64 * verdict::samples_memory(resolution) + verdict::sampling_memory(0),
        allow_large,
        "ask for a smaller resolution (its samples grow as its square) or fewer threads, or \
         allow_large=True",
    )?;
    // Ctrl-C (KeyboardInterrupt) is heard within a component's time.
    let found = interruptible(py, &pool, |stop| {
        bodies
            .par_iter()
            .with_max_len(1)
            .map(|b| verdict::verdict_until(b, &options, stop))
            .collect::<Vec<_>>()
    })?;
    found
        .into_iter()
        .map(|v| serde_json::to_string(&v.map_err(value_error)?).map_err(|e| bad(e.to_string())))
        .collect()
}

/// The β at which the verdict changes along β at one α (`verdict --boundaries`), as the
/// command's JSON, computed with the GIL released.
#[pyfunction]
#[pyo3(signature = (alpha, nu, eta, beta_min, beta_max, scan, tol, resolution, threads=None))]
#[allow(clippy::too_many_arguments)]
fn boundaries(
    py: Python<'_>,
    alpha: f64,
    nu: f64,
    eta: f64,
    beta_min: f64,
    beta_max: f64,
    scan: i64,
    tol: f64,
    resolution: i64,
    threads: Option<i64>,
) -> PyResult<String> {
    // (A negative scan is out of the library's range too, and named as given: "must be
    // >= 1" for 0 was followed by 1 refused as below 4.)
    let scan = usize::try_from(scan)
        .ok()
        .filter(|s| verdict::BOUNDARY_SCANS.contains(s))
        .ok_or_else(|| {
            bad(format!(
                "invalid scan = {scan}: must be between 4 and 10000"
            ))
        })?;
    let resolution = resolution_between(resolution, 32, " for the boundaries")?;
    let pool = pool(threads)?;
    let options = verdict::BoundaryOptions {
        beta_min,
        beta_max,
        scan,
        verdict: VerdictOptions {
            tol,
            resolution,
            counterexamples: true,
            coarse_first: false,
        },
    };
    let found = interruptible(py, &pool, |stop| {
        verdict::boundaries_until(alpha, nu, eta, &options, stop)
    })?
    .map_err(value_error)?;
    serde_json::to_string(&found).map_err(|e| bad(e.to_string()))
}

/// The long name, units and comment of a coordinate (`alpha`, …, `energy`, `component`).
#[pyfunction]
fn coordinate(name: &str) -> PyResult<(&'static str, &'static str, Option<&'static str>)> {
    let (long_name, units) =
        atlas::coordinate(name).ok_or_else(|| bad(format!("no coordinate {name:?}")))?;
    Ok((long_name, units.units, units.comment))
}

/// The root attributes of a result made by `call` (a Python call, as text): the program, its
/// version and commit, the CF conventions and `history`.
#[pyfunction]
fn provenance(call: &str) -> Vec<(String, String)> {
    let mut out = vec![(
        "Conventions".to_string(),
        crate::cf::CONVENTIONS.to_string(),
    )];
    out.extend(
        crate::store::program_attributes()
            .into_iter()
            .map(|(k, v)| (k, v.display())),
    );
    out.push(("history".to_string(), crate::cf::history(call)));
    out
}

/// A profile's table as the files hold it: one `rho z edge` row a line from the lower pole
/// ([`crate::Profile::text`]); a table that is no convex meridian is a ValueError.
#[pyfunction]
fn profile_text(rows: Vec<Vec<f64>>) -> PyResult<String> {
    Ok(crate::Profile::from_points(&rows)
        .map_err(value_error)?
        .text())
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // NumPy's C API is looked up (and kept) now, on import: looked up first while a
    // Ctrl-C was pending (a long `diagram` as the first call), it failed inside the numpy
    // crate, which panics on that.
    PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("git_commit", env!("RUBBER_ATLAS_GIT_COMMIT"))?;
    m.add("COMPONENT_SLOTS", COMPONENT_SLOTS)?;
    m.add("FIELDS", Field::ALL.map(|f| f.name()).to_vec())?;
    m.add_function(wrap_pyfunction!(variables, m)?)?;
    m.add_function(wrap_pyfunction!(memory_short, m)?)?;
    m.add_function(wrap_pyfunction!(coordinate, m)?)?;
    m.add_function(wrap_pyfunction!(provenance, m)?)?;
    m.add_function(wrap_pyfunction!(cells, m)?)?;
    m.add_function(wrap_pyfunction!(profile_text, m)?)?;
    m.add_function(wrap_pyfunction!(bottoms, m)?)?;
    m.add_function(wrap_pyfunction!(diagram, m)?)?;
    m.add_function(wrap_pyfunction!(trajectory, m)?)?;
    m.add_function(wrap_pyfunction!(resonance, m)?)?;
    m.add_function(wrap_pyfunction!(verdicts, m)?)?;
    m.add_function(wrap_pyfunction!(census, m)?)?;
    m.add_function(wrap_pyfunction!(boundaries, m)?)?;
    Ok(())
}
