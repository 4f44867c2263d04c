//! The library's typed errors: every way an input or a computation can be refused, with the
//! offending value named so that the command line can print one clear line.

use thiserror::Error;

/// Everything the library can refuse or fail at.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum AtlasError {
    /// A parameter outside its allowed range, or not a finite number.
    #[error("invalid {name} = {}: {reason}", show(*value))]
    InvalidParameter {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    /// The energy is below every value of the effective potential: no motion at all.
    #[error(
        "no motion: energy {} is below the minimum {} of the effective potential",
        show(*energy),
        show(*minimum)
    )]
    NoMotion { energy: f64, minimum: f64 },
    /// An initial angle outside the allowed set (κ ≠ 0 needs 0 < θ < π).
    #[error("invalid theta0 = {}: {reason}", show(*theta0))]
    InvalidInitialAngle { theta0: f64, reason: &'static str },
    /// The ODE integrator gave up.
    #[error("integration failed at t = {}: {reason}", show(*time))]
    Integration { time: f64, reason: String },
    /// A quantity that needs an oscillating component (a period) was asked of a fixed point
    /// or of motion that is not periodic in θ.
    #[error("no θ-period: {reason}")]
    NotPeriodic { reason: &'static str },
    /// A value the computation could not resolve in double precision: a failed computation
    /// (the command's exit 1), not a bad input.
    #[error("{what} could not be computed: {reason}")]
    Unresolved {
        what: &'static str,
        reason: &'static str,
    },
    /// Writing an output file failed.
    #[error("cannot write {path}: {reason}")]
    Output { path: String, reason: String },
    /// A scene file that cannot be read or is not valid: the file, the key and the reason.
    #[error("{file}: {key}: {reason}")]
    Scene {
        file: String,
        key: String,
        reason: String,
    },
    /// An atlas file, a shard or a resume journal that cannot be used as asked.
    #[error("{path}: {reason}")]
    Atlas { path: String, reason: String },
    /// A file the work was writing failed part-way (the resume journal, the partial atlas
    /// file, its rename into place): a failed run (the command's exit 1), not a bad input.
    #[error("{path}: {reason}")]
    WriteFailed { path: String, reason: String },
    /// A request larger than this machine can hold (the caller may insist).
    #[error("{reason}")]
    TooLarge { reason: String },
    /// Another process is writing the same output.
    #[error("{path}: {reason}")]
    Busy { path: String, reason: String },
    /// A run was asked to stop (SIGINT, SIGTERM): the units computed so far are in the
    /// journal and a resumed run continues from them.
    #[error("{path}: interrupted with {done} of {total} cells computed and kept")]
    Interrupted { path: String, done: u64, total: u64 },
    /// A request this body or method does not support (yet): what, and why.
    #[error("{what}: {reason}")]
    Unsupported {
        what: &'static str,
        reason: &'static str,
    },
    /// A computation given up because its caller asked it to stop (Ctrl-C in Python).
    #[error("stopped on request")]
    Stopped,
    /// A table of a meridian (a body of the user's own) that is not a convex profile the
    /// program can follow: the point and the reason.
    #[error("invalid profile: the table {reason}")]
    Profile { reason: String },
}

impl AtlasError {
    /// An [`AtlasError::Atlas`] naming `path`.
    #[cfg_attr(not(feature = "hdf5"), allow(dead_code))]
    pub(crate) fn atlas(path: &std::path::Path, reason: impl std::fmt::Display) -> Self {
        AtlasError::Atlas {
            path: path.display().to_string(),
            reason: reason.to_string(),
        }
    }

    /// An [`AtlasError::WriteFailed`] naming `path`.
    #[cfg_attr(not(feature = "hdf5"), allow(dead_code))]
    pub(crate) fn write_failed(path: &std::path::Path, reason: impl std::fmt::Display) -> Self {
        AtlasError::WriteFailed {
            path: path.display().to_string(),
            reason: reason.to_string(),
        }
    }
}

/// A number as a person reads it in a message: exponent notation far from 1 (1e200, not
/// two hundred digits).
pub fn show(value: f64) -> String {
    if value != 0.0 && value.is_finite() && !(1e-4..1e16).contains(&value.abs()) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

/// The most rows a table (`diagram`, `trajectory`) may have, whatever memory the machine
/// has: at a few hundred bytes a row, 1e8 rows are tens of GB already.
pub const MAX_SAMPLES: usize = 100_000_000;

/// Refuses a table of `samples` rows outside 1 ..= [`MAX_SAMPLES`].
pub(crate) fn check_samples(samples: usize) -> Result<()> {
    if samples == 0 || samples > MAX_SAMPLES {
        return Err(AtlasError::InvalidParameter {
            name: "samples",
            value: samples as f64,
            reason: "must be between 1 and 1e8",
        });
    }
    Ok(())
}

/// A number with `digits` digits after the point as a person reads it: exponent notation far
/// from 1 (1.5e300, not three hundred digits), fixed notation near it.
pub fn show_digits(value: f64, digits: usize) -> String {
    if value != 0.0 && value.is_finite() && !(1e-4..1e6).contains(&value.abs()) {
        format!("{value:.digits$e}")
    } else {
        format!("{value:.digits$}")
    }
}

/// The largest |κ| any surface takes: κ² (and κ²/sin²θ near the poles) stays far from overflow.
pub const MAX_KAPPA: f64 = 1e150;

/// The largest |ε| any surface takes (a scene's (λ, s) plane reaches it at s = 1e-150).
pub const MAX_ENERGY: f64 = 1e300;

/// Refuses an ε that is not finite or above [`MAX_ENERGY`] in size.
pub(crate) fn check_energy(energy: f64) -> Result<f64> {
    check_range(
        "energy",
        energy,
        Some((-MAX_ENERGY, true)),
        Some((MAX_ENERGY, true)),
        "|energy| must be at most 1e300",
    )
}

/// Refuses a κ that is not finite, above [`MAX_KAPPA`] in size, or subnormal (0 < |κ| <
/// 2.2e-308: κ² underflows to 0 while the turning points next to the poles, at about κ/√(2ε),
/// have no normal double left to be found at).
pub(crate) fn check_kappa(kappa: f64) -> Result<f64> {
    check_range(
        "kappa",
        kappa,
        Some((-MAX_KAPPA, true)),
        Some((MAX_KAPPA, true)),
        "|kappa| must be at most 1e150 (kappa^2 would overflow)",
    )?;
    if kappa != 0.0 && kappa.abs() < f64::MIN_POSITIVE {
        return Err(AtlasError::InvalidParameter {
            name: "kappa",
            value: kappa,
            reason: "is subnormal: give 0 or |kappa| >= 2.2250738585072014e-308 (the least normal double)",
        });
    }
    Ok(kappa)
}

/// Shorthand for results of this crate.
pub type Result<T> = std::result::Result<T, AtlasError>;

/// Checks that `value` is finite and lies in the interval described by `lower`/`upper`
/// (each bound `Some((bound, inclusive))` or `None`), naming the parameter in the error.
pub(crate) fn check_range(
    name: &'static str,
    value: f64,
    lower: Option<(f64, bool)>,
    upper: Option<(f64, bool)>,
    reason: &'static str,
) -> Result<f64> {
    let fail = || AtlasError::InvalidParameter {
        name,
        value,
        reason,
    };
    if !value.is_finite() {
        return Err(AtlasError::InvalidParameter {
            name,
            value,
            reason: "must be a finite number",
        });
    }
    if let Some((lo, inclusive)) = lower {
        if value < lo || (!inclusive && value == lo) {
            return Err(fail());
        }
    }
    if let Some((hi, inclusive)) = upper {
        if value > hi || (!inclusive && value == hi) {
            return Err(fail());
        }
    }
    Ok(value)
}
