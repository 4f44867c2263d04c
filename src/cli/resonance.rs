//! `rubber-atlas resonance`: resonance curves N = P/Q by continuation, or the fold κ_max.

use super::*;
use anyhow::Result;
use clap::Args;
use rubber_atlas::cf::AttrValue;
use rubber_atlas::error::AtlasError;
use rubber_atlas::resonance::{self, ResonanceOptions};
use rubber_atlas::store::{check_output, write_table_until};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct ResonanceArgs {
    #[command(flatten)]
    pub shape: BodyShapeArgs,
    /// ν = i3/i1, 0 < ν <= 2.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub nu: f64,
    /// η = m b3²/i1 > 0.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub eta: f64,
    /// The rotation number of the curves: P/Q (e.g. 0, 1, -1/7) or a decimal.
    #[arg(long, value_name = "P/Q", allow_hyphen_values = true)]
    pub rotation_number: String,
    /// The window: smallest κ (> 0; N = 0 at κ = 0).
    #[arg(value_parser = number, long, default_value_t = 0.01, allow_hyphen_values = true)]
    pub kappa_min: f64,
    /// The window: largest κ.
    #[arg(value_parser = number, long, default_value_t = 2.0, allow_hyphen_values = true)]
    pub kappa_max: f64,
    /// The window: smallest ε [default: the lowest minimum of V over the window].
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub energy_min: Option<f64>,
    /// The window: largest ε.
    #[arg(value_parser = number, long, default_value_t = 5.0, allow_hyphen_values = true)]
    pub energy_max: f64,
    /// Rows of κ (and energies per row) of the seed scan; curves are also followed between
    /// rows, but a closed curve that crosses no row is missed.
    #[arg(long, default_value_t = 48, allow_hyphen_values = true)]
    pub grid: usize,
    /// Tolerance of the cell solver (N on the curve equals P/Q to this; at most 1e-4).
    #[arg(value_parser = number, long, default_value_t = 1e-10, allow_hyphen_values = true)]
    pub tol: f64,
    /// Print the top (largest κ) of the curve of largest κ as JSON {"kappa_max": …, "energy":
    /// …, "fold": {"top": …}}: "fold" where ∂N/∂ε = 0 there, "corner" where the curve turns
    /// sharply there (at a cusp) or ends (at a separatrix).
    #[arg(long)]
    pub fold: bool,
    /// Print the curves as JSON.
    #[arg(long, conflicts_with = "out")]
    pub json: bool,
    /// Write the curves to FILE (.csv, .h5 or .hdf5), one row per point.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Overwrite an existing --out file.
    #[arg(long)]
    pub force: bool,
}

/// A whole number in decimal, with its sign; one of more than 30 digits as the largest i128
/// (beyond any bound it is checked against).
fn whole_number(text: &str) -> Option<i128> {
    let text = text.trim();
    let (negative, digits) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text.strip_prefix('+').unwrap_or(text)),
    };
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let size = if digits.len() > 30 {
        i128::MAX
    } else {
        digits.parse().ok()?
    };
    Some(if negative { -size } else { size })
}

/// P/Q or a decimal.
pub(super) fn parse_rotation_number(text: &str) -> Result<f64> {
    let bad = || AtlasError::Atlas {
        path: format!("--rotation-number {text}"),
        reason: "expected P/Q with whole numbers P and Q != 0, or a number".into(),
    };
    let value = match text.split_once('/') {
        Some((p, q)) => {
            // (A whole number beyond i64 is refused below as too large, not as "not whole
            // numbers": adversary pass 42.)
            let (Some(p), Some(q)) = (whole_number(p), whole_number(q)) else {
                return Err(bad().into());
            };
            if q == 0 {
                return Err(bad().into());
            }
            // Up to 2^53 every whole number is a double, and p/q is rounded once.
            const EXACT: u128 = 1 << 53;
            if p.unsigned_abs() > EXACT || q.unsigned_abs() > EXACT {
                return Err(AtlasError::Atlas {
                    path: format!("--rotation-number {text}"),
                    reason: "P and Q must be at most 2^53 = 9007199254740992 in size (beyond, \
                             whole numbers are not all doubles)"
                        .into(),
                }
                .into());
            }
            p as f64 / q as f64
        }
        None => text.trim().parse::<f64>().map_err(|_| bad())?,
    };
    if !value.is_finite() {
        return Err(bad().into());
    }
    // (−0 is 0: the text printed "N = -0"; adversary pass of 2026-11-28.)
    Ok(value + 0.0)
}

pub(super) fn resonance(args: ResonanceArgs) -> Result<()> {
    if let Some(out) = &args.out {
        check_output(out, args.force, &[], &TABLE_EXTENSIONS)?;
    }
    if args.fold && args.out.is_some() {
        return Err(AtlasError::Atlas {
            path: "resonance".into(),
            reason: "--fold prints the fold as JSON; it does not go with --out".into(),
        }
        .into());
    }
    let body = args.shape.body(args.nu, args.eta)?;
    let target = parse_rotation_number(&args.rotation_number)?;
    let options = rubber_atlas::with_body!(&body, b => ResonanceOptions::window(
        b,
        target,
        (args.kappa_min, args.kappa_max),
        args.energy_min,
        args.energy_max,
        args.grid,
        args.tol,
    ));
    // The ellipsoid's header as it always was; another shape adds its name and parameters.
    let mut header = serde_json::Value::Object(body_json(&body));
    for (key, value) in [
        ("nu", serde_json::json!(args.nu)),
        ("eta", serde_json::json!(args.eta)),
        ("rotation_number", serde_json::json!(target)),
        (
            "kappa_window",
            serde_json::json!([options.kappa.0, options.kappa.1]),
        ),
        (
            "energy_window",
            serde_json::json!([options.energy.0, options.energy.1]),
        ),
        ("tolerance", serde_json::json!(args.tol)),
    ] {
        header[key] = value;
    }
    // On a body that is its own mirror image in its equatorial plane, N = 0 on every torus
    // that spans both halves: a region of the plane, not a curve (its tori run away). Said
    // so, rather than "no component reaches N = 0" (adversary pass of 2026-11-28).
    let zero_region = target == 0.0
        && rubber_atlas::with_body!(&body, b => rubber_atlas::Shape::symmetric_about_equator(&b.shape));
    const ZERO_REGION: &str = "this body is symmetric about its equator: N = 0 on every torus \
        that spans both halves (a region of the plane, not a curve), and those paths run away; \
        the curves below are where N = 0 on the other tori";
    if zero_region {
        header["note"] = serde_json::json!(ZERO_REGION);
    }
    if args.fold {
        let fold = rubber_atlas::with_body!(&body, b => resonance::fold_until(
            b,
            &options,
            &crate::stop::requested
        ))?;
        let mut value = header;
        match fold {
            Some(f) => {
                value["kappa_max"] = serde_json::json!(f.kappa_max);
                value["energy"] = serde_json::json!(f.energy);
                value["fold"] = serde_json::to_value(f)?;
            }
            None => {
                value["kappa_max"] = serde_json::Value::Null;
                value["energy"] = serde_json::Value::Null;
                value["reason"] = serde_json::json!(
                    "no N = P/Q curve in the window, or the curve of largest kappa leaves it \
                     through kappa_max (widen --kappa-max), or that curve is a single point (it \
                     could not be followed from its seed)"
                );
            }
        }
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    let curves = rubber_atlas::with_body!(&body, b => resonance::trace_curves_until(
        b,
        &options,
        &crate::stop::requested
    ))?;
    if args.json {
        let mut value = header;
        value["curves"] = serde_json::to_value(&curves)?;
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    if let Some(out) = &args.out {
        let mut table = rubber_atlas::table::resonance(&curves);
        let mut attributes = body_fields(&body);
        attributes.extend([
            ("nu", AttrValue::Number(args.nu)),
            ("eta", AttrValue::Number(args.eta)),
            ("rotation_number", AttrValue::Number(target)),
            ("tolerance", AttrValue::Number(args.tol)),
            ("header_json", AttrValue::Text(header.to_string())),
        ]);
        table.attributes.extend(table_attributes(&attributes));
        write_table_until(out, &table, &crate::stop::requested)?;
        println!(
            "wrote {} curves ({} points) to {}",
            curves.len(),
            curves.iter().map(|c| c.points.len()).sum::<usize>(),
            out.display()
        );
        return Ok(());
    }
    let shown = show(target);
    println!(
        "N = {shown} for {} nu={} eta={}: {} curve(s) in kappa [{}, {}], energy [{}, {}]",
        body_text(&body),
        show(args.nu),
        show(args.eta),
        curves.len(),
        show(options.kappa.0),
        show(options.kappa.1),
        digits(options.energy.0, 6),
        show(options.energy.1)
    );
    if zero_region {
        println!("  ({ZERO_REGION})");
    }
    if curves.is_empty() && !zero_region {
        println!(
            "  (no component reaches N = {shown} on the seed grid of this window: the curve may \
             lie beyond the window (widen it with --kappa-max and --energy-max), or between the \
             grid's rows (kappa step {}, energy step {}: raise --grid); see where N takes this \
             value with an atlas or `rubber-atlas verdict`)",
            digits(
                (options.kappa.1 - options.kappa.0) / (options.grid as f64 - 1.0),
                3
            ),
            digits(
                (options.energy.1 - options.energy.0) / (options.grid as f64 - 1.0),
                3
            )
        );
    }
    for (i, c) in curves.iter().enumerate() {
        let (kmin, kmax) = c
            .points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.kappa), b.max(p.kappa))
            });
        let (emin, emax) = c
            .points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.energy), b.max(p.energy))
            });
        println!(
            "[{i}] {} points{}, well theta = {:.6}, kappa in [{}, {}], energy in [{}, {}]",
            c.points.len(),
            if c.closed { " (closed)" } else { "" },
            c.points[0].well,
            digits(kmin, 6),
            digits(kmax, 6),
            digits(emin, 6),
            digits(emax, 6)
        );
    }
    Ok(())
}
