//! `rubber-atlas diagram`: the critical set of one body (paper §4), printed, as JSON or as a
//! table file.

use super::*;
use anyhow::{Context, Result};
use clap::Args;
use rubber_atlas::cf::AttrValue;
use rubber_atlas::critical::CriticalSet;
use rubber_atlas::store::{check_output, write_table_until};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct DiagramArgs {
    #[command(flatten)]
    pub shape: BodyShapeArgs,
    /// ν = i3/i1 (does not change the critical set; recorded in the output); with --eta, or
    /// both left at 0.5, so that no value the user did not give is recorded beside one given.
    #[arg(
        value_parser = number,
        long,
        default_value_t = 0.5,
        allow_hyphen_values = true,
        requires = "eta"
    )]
    pub nu: f64,
    /// η = m b3²/i1 (does not change the critical set; recorded in the output); with --nu.
    #[arg(
        value_parser = number,
        long,
        default_value_t = 0.5,
        allow_hyphen_values = true,
        requires = "nu"
    )]
    pub eta: f64,
    /// Print the critical set as one JSON object.
    #[arg(long, conflicts_with = "out")]
    pub json: bool,
    /// Write the sampled curves to FILE (.csv, .h5 or .hdf5).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Overwrite an existing --out file.
    #[arg(long)]
    pub force: bool,
    /// Samples of θ0 per half (θ0 < π/2, θ0 > π/2) of the fixed-point curves, evenly in θ0
    /// (plus eight a decade towards the poles and π/2 where the body turns on a finer scale,
    /// as a far oblate or prolate ellipsoid): written by --out; with --json or the text,
    /// each branch's ranges of θ0, κ, ε and N are found over them, N's extremes located
    /// between samples (the default is plenty there; more only costs time).
    #[arg(long, default_value_t = 2000, allow_hyphen_values = true)]
    pub samples: usize,
    #[command(flatten)]
    pub limits: Limits,
    /// Truncate the sampled curves at this κ (1e-20 to 1e150).
    #[arg(value_parser = number, long, default_value_t = 3.0, allow_hyphen_values = true)]
    pub kappa_max: f64,
}

pub(super) fn diagram(args: DiagramArgs) -> Result<()> {
    if let Some(out) = &args.out {
        check_output(out, args.force, &[], &TABLE_EXTENSIONS)?;
    }
    // Measured: 245 bytes of memory per sample at the peak, 2 points per sample of about
    // 150 bytes each in a CSV file.
    let per_sample = 300.0 * args.samples as f64;
    args.limits.check(
        per_sample,
        args.out.as_ref().map(|_| per_sample),
        args.out.as_deref(),
        &|| "use fewer --samples".into(),
    )?;
    let body = args.shape.body(args.nu, args.eta)?;
    let set = CriticalSet::of_any(&body, args.samples, args.kappa_max, &crate::stop::requested)?;
    if args.json {
        let text = serde_json::to_string_pretty(&set)?;
        if crate::stop::requested() {
            return Err(AtlasError::Stopped.into());
        }
        println!("{text}");
        return Ok(());
    }
    if let Some(out) = &args.out {
        write_diagram(out, &set)?;
        say!(
            "wrote {} points on {} branches to {}",
            set.branches.iter().map(|b| b.points.len()).sum::<usize>(),
            set.branches.len(),
            out.display()
        );
    }
    print_diagram(&set);
    Ok(())
}

/// The shape and its parameters as the diagram's first line names them.
fn body_words(set: &CriticalSet) -> String {
    let mut words = format!(
        "{} alpha = {}",
        set.shape.unwrap_or("ellipsoid"),
        show(set.alpha)
    );
    for (name, value) in [("beta", set.beta), ("cut", set.cut)] {
        if let Some(v) = value {
            words += &format!(", {name} = {}", show(v));
        }
    }
    words
}

pub(super) fn print_diagram(set: &CriticalSet) {
    let kind = match set.diagram_type {
        Some(t) => format!("diagram type ({})", t.label()),
        None => "no diagram type (the types (a)-(e) are the ellipsoid's)".into(),
    };
    println!(
        "{} (nu = {}, eta = {}): {kind}",
        body_words(set),
        show(set.nu),
        show(set.eta)
    );
    for k in &set.kinks {
        println!("  kink of U (the contact passes an edge) at theta = {k:.12}");
    }
    println!(
        "  eps_min (roll over the top at kappa = 0) = {}",
        digits(set.energy_min, 12)
    );
    if let Some(t) = set.theta_star {
        println!("  inclined equilibrium theta* = {t:.12}");
    }
    for e in &set.equilibria {
        if let Some(end) = e.theta_end {
            println!(
                "  equilibria  {:<10} theta = {:.12} ... {:.12}  eps = {}  neutral (U' = 0 on the arc)",
                e.name,
                e.theta,
                end,
                digits(e.energy, 12)
            );
            continue;
        }
        println!(
            "  equilibrium {:<10} theta = {:.12}  eps = {}  {}{}",
            e.name,
            e.theta,
            digits(e.energy, 12),
            if e.stable { "stable" } else { "unstable" },
            if e.isolated { ", isolated" } else { "" }
        );
    }
    let cusps = if set.cusps.is_empty() {
        set.cusp.iter().copied().collect()
    } else {
        set.cusps.clone()
    };
    for c in &cusps {
        println!(
            "  cusp theta_c = {:.12}  kappa_c = {}  eps_c = {}",
            c.theta,
            digits(c.kappa, 12),
            digits(c.energy, 12)
        );
    }
    if set.diagram_type == Some(rubber_atlas::critical::DiagramType::C) && cusps.is_empty() {
        // σ_u climbing to κ_max without meeting σ_s0: the cusp lies above κ_max.
        // (Where the equator stands for the rotations by it, σ_π/2's unstable run does.)
        let above = set
            .branches
            .iter()
            .find(|b| !b.stable && b.kappa_range[1] >= set.kappa_max * (1.0 - 1e-6));
        if let Some(branch) = above {
            println!(
                "  cusp above kappa_max = {}: {} reaches it without meeting sigma_s0",
                digits(set.kappa_max, 12),
                branch.name
            );
        } else {
            println!(
                "  cusp not resolved below kappa_max = {}: it lies above, or sigma_u lies \
                 within the sampling (or the spacing of doubles) of theta = pi/2 at this alpha",
                digits(set.kappa_max, 12)
            );
        }
    }
    for c in &set.stability_changes_at_kinks {
        println!(
            "  stability changes at the kink theta = {:.12}  kappa = {}  eps = {}",
            c.theta,
            digits(c.kappa, 12),
            digits(c.energy, 12)
        );
    }
    if let Some(k) = set.kappa_c_equator {
        println!("  equator sigma_pi2 stable for |kappa| > {}", digits(k, 12));
    }
    for b in &set.branches {
        let bottom = b
            .rotation_number_range
            .map(|[lo, hi]| {
                format!(
                    "  N at the bottom in [{}, {}]",
                    digits(lo, 6),
                    digits(hi, 6)
                )
            })
            .unwrap_or_default();
        println!(
            "  branch {:<10} {:<8} theta0 in [{}, {}]  kappa in [{}, {}]  eps in [{}, {}]{bottom}",
            b.name,
            if b.stable { "stable" } else { "unstable" },
            digits(b.theta0_range[0], 6),
            digits(b.theta0_range[1], 6),
            digits(b.kappa_range[0], 6),
            digits(b.kappa_range[1], 6),
            digits(b.energy_range[0], 6),
            digits(b.energy_range[1], 6)
        );
    }
}

pub(super) fn write_diagram(out: &std::path::Path, set: &CriticalSet) -> Result<()> {
    let Some(mut table) = rubber_atlas::table::diagram_until(set, &crate::stop::requested) else {
        return Err(AtlasError::Stopped.into());
    };
    let mut attributes = Vec::new();
    if let Some(shape) = set.shape {
        attributes.push(("shape", AttrValue::Text(shape.to_string())));
    }
    attributes.push(("alpha", AttrValue::Number(set.alpha)));
    for (name, value) in [("beta", set.beta), ("cut", set.cut)] {
        if let Some(v) = value {
            attributes.push((name, AttrValue::Number(v)));
        }
    }
    attributes.extend([
        ("nu", AttrValue::Number(set.nu)),
        ("eta", AttrValue::Number(set.eta)),
        (
            "critical_set_json",
            AttrValue::Text(serde_json::to_string(set)?),
        ),
    ]);
    table.attributes.extend(table_attributes(&attributes));
    write_table_until(out, &table, &crate::stop::requested)
        .with_context(|| format!("writing the diagram of {}", body_words(set)))?;
    Ok(())
}
