//! `rubber-atlas verdict`: the boundedness hypothesis for one body, or the β where its verdict
//! changes along β.

use crate::cli::{number, BodyShapeArgs, ShapeKindArg};
use anyhow::Result;
use clap::Args;
use rubber_atlas::error::{show, show_digits as digits, AtlasError};
use rubber_atlas::verdict::{self, VerdictOptions};
use rubber_atlas::AnyBody;
use std::io::IsTerminal;

#[derive(Debug, Args)]
pub struct VerdictArgs {
    /// α = a/b3: displacement of the centre of mass along the axis, 0 <= α < 1 (α < 0 is the
    /// mirror image θ -> π - θ of -α).
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub alpha: f64,
    /// β = b1/b3 (not with --boundaries).
    #[arg(
        long,
        value_parser = number,
        allow_hyphen_values = true,
        required_unless_present_any = ["boundaries", "shape"],
        conflicts_with = "boundaries"
    )]
    pub beta: Option<f64>,
    /// Another body (disk, truncated_ball, wheel, profile; docs/bodies.md): not the paper's
    /// hypothesis, which is the ellipsoid's, but which integers N reaches over its whole
    /// (κ, ε) plane, with points where the path runs away.
    #[arg(long, value_enum, conflicts_with = "boundaries")]
    pub shape: Option<ShapeKindArg>,
    /// h of the cut balls (--shape truncated_ball or wheel).
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub cut: Option<f64>,
    /// The meridian's table of --shape profile.
    #[arg(long, value_name = "FILE")]
    pub profile: Option<std::path::PathBuf>,
    /// ν = i3/i1, 0 < ν <= 2.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub nu: f64,
    /// η = m b3²/i1 > 0.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub eta: f64,
    /// The β at which the verdict changes along β at this α, each by root-finding.
    #[arg(long)]
    pub boundaries: bool,
    /// Smallest β searched by --boundaries [default: 0.05].
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub beta_min: Option<f64>,
    /// Largest β searched by --boundaries [default: 50].
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub beta_max: Option<f64>,
    /// Log-spaced β of the scan behind --boundaries (the line β² = 1 + α is added)
    /// [default: 48].
    #[arg(long, allow_hyphen_values = true)]
    pub scan: Option<usize>,
    /// Tolerance of the cell solver (N at a counterexample equals the integer to this).
    #[arg(value_parser = number, long, default_value_t = 1e-10, allow_hyphen_values = true)]
    pub tol: f64,
    /// κ-lines of each kind and energies per line of the sampling (doubling it halves the
    /// spacing), 8 … 4096 (32 … 4096 with --boundaries); the time grows about as its square
    /// (the paper's body: 0.5 s at 64, about 9 minutes at 4096).
    #[arg(long, default_value_t = 64, allow_hyphen_values = true, value_parser = resolution)]
    pub resolution: usize,
    /// Print one JSON object (docs/hypothesis.md contract).
    #[arg(long)]
    pub json: bool,
}

pub(super) fn verdict(args: VerdictArgs) -> Result<()> {
    let options = VerdictOptions {
        tol: args.tol,
        resolution: args.resolution,
        counterexamples: true,
        coarse_first: false,
    };
    if !args.boundaries
        && (args.beta_min.is_some() || args.beta_max.is_some() || args.scan.is_some())
    {
        return Err(AtlasError::Atlas {
            path: "verdict".into(),
            reason: "--beta-min, --beta-max and --scan go with --boundaries".into(),
        }
        .into());
    }
    if args.boundaries {
        let defaults = verdict::BoundaryOptions::default();
        // A bar on a terminal (the search takes a minute or two): the scan's verdicts, then
        // the changes being located; elsewhere (a batch job's log) a plain line every ten
        // seconds, as `run` prints.
        let terminal = std::io::stderr().is_terminal();
        let bar = if terminal {
            indicatif::ProgressBar::new(0)
        } else {
            indicatif::ProgressBar::hidden()
        };
        let started = std::time::Instant::now();
        let last_line = std::sync::Mutex::new(started);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} ({elapsed})")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        let found = verdict::boundaries_with(
            args.alpha,
            args.nu,
            args.eta,
            &verdict::BoundaryOptions {
                beta_min: args.beta_min.unwrap_or(defaults.beta_min),
                beta_max: args.beta_max.unwrap_or(defaults.beta_max),
                scan: args.scan.unwrap_or(defaults.scan),
                verdict: options,
            },
            &crate::stop::requested,
            &|at| {
                let (message, done, of) = match at {
                    verdict::BoundarySearch::Scanned { done, of } => {
                        ("verdicts along beta", done, of)
                    }
                    verdict::BoundarySearch::Locating { index, of } => {
                        ("locating the changes", index - 1, of)
                    }
                };
                bar.set_message(message);
                bar.set_length(of as u64);
                bar.set_position(done as u64);
                if !terminal {
                    let mut last = last_line.lock().unwrap_or_else(|e| e.into_inner());
                    if last.elapsed() >= std::time::Duration::from_secs(10) {
                        *last = std::time::Instant::now();
                        say!(
                            "verdict --boundaries: {message} {done}/{of} ({:.0} s)",
                            started.elapsed().as_secs_f64()
                        );
                    }
                }
            },
        );
        bar.finish_and_clear();
        let found = found?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&found)?);
        } else {
            println!(
                "alpha = {} (nu = {}, eta = {}): the verdict along beta in [{}, {}]",
                found.alpha, found.nu, found.eta, found.beta_range[0], found.beta_range[1]
            );
            let side = |c: verdict::Case, h: Option<bool>| match h {
                None if c == verdict::Case::NotCovered => "not covered".to_string(),
                None => format!(
                    "case {} undecided",
                    serde_json::to_value(c)
                        .unwrap_or_default()
                        .as_str()
                        .unwrap_or("?")
                ),
                Some(h) => format!(
                    "case {} {}",
                    serde_json::to_value(c)
                        .unwrap_or_default()
                        .as_str()
                        .unwrap_or("?"),
                    if h { "holds" } else { "fails" }
                ),
            };
            for b in &found.boundaries {
                println!(
                    "  beta = {:.10} +- {:.1e}: {} below, {} above ({})",
                    b.beta,
                    b.error,
                    side(b.case_below, b.holds_below),
                    side(b.case_above, b.holds_above),
                    b.quantity
                );
            }
            if found.boundaries.is_empty() {
                // (Only the header was printed: an adversary pass.)
                println!(
                    "  no boundary found: the verdict is the same at every beta of the scan \
                     (--scan sets how many)"
                );
            }
        }
        return Ok(());
    }
    // The body as every command takes it (a parameter the shape does not take, or one it
    // needs, refused in one line): the ellipsoid's verdict, or another shape's census.
    let body = BodyShapeArgs {
        shape: args.shape.unwrap_or(ShapeKindArg::Ellipsoid),
        alpha: args.alpha,
        beta: args.beta,
        cut: args.cut,
        profile: args.profile.clone(),
    }
    .body(args.nu, args.eta)?;
    let body = match body {
        AnyBody::Ellipsoid(b) => b,
        other => return census(&args, &other),
    };
    let options = VerdictOptions {
        coarse_first: true,
        ..options
    };
    let v = verdict::verdict_until(&body, &options, &crate::stop::requested)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    print_verdict(&v);
    Ok(())
}

pub(super) fn print_verdict(v: &verdict::Verdict) {
    use verdict::Case;
    println!(
        "ellipsoid alpha = {}, beta = {} (nu = {}, eta = {}): diagram type ({})",
        show(v.alpha),
        show(v.beta),
        show(v.nu),
        show(v.eta),
        v.diagram_type.label()
    );
    let case = match v.case {
        Case::One => "case 1 (beta^2 < 1 + alpha): bounded for every kappa != 0",
        Case::Two => "case 2 (beta^2 > 1 + alpha, alpha > 0): bounded for kappa > kappa_max",
        Case::NotCovered => {
            "not covered by the hypothesis (alpha = 0 with beta >= 1, or beta^2 = 1 + alpha)"
        }
    };
    println!("  hypothesis: {case}");
    if let (Some(k), Some(e)) = (v.kappa_max, v.kappa_max_error) {
        println!(
            "  kappa_max = {} (+- {e:.1e}), the fold of the N = 0 curve beside sigma_u",
            digits(k, 10)
        );
    }
    let h = &v.high_energy;
    if h.slope.is_nan() {
        println!("  high energy: not computed");
    } else {
        println!(
        "  high energy: N_inf(lambda) ~ {:.6e} lambda at lambda -> 0; min {:.10} at lambda = {:.6}; max {:.10} at lambda = {:.6}",
        h.slope,
        h.n_min,
        h.lambda_at_min,
        h.n_max,
        h.lambda_at_max
    );
    }
    match v.holds {
        None => match &v.evidence.undecided {
            Some(why) => println!("  verdict: UNDECIDED ({why})"),
            None => println!("  verdict: not covered"),
        },
        Some(true) => println!("  verdict: HOLDS (fail margin {:.3e})", v.fail_margin),
        Some(false) => println!("  verdict: FAILS (fail margin {:.3e})", v.fail_margin),
    }
    if let Some(reason) = &v.evidence.limit_failure {
        println!("  by the limit: {reason}");
    }
    for c in &v.counterexamples {
        println!(
            "  counterexample: N = {} at kappa = {}, energy = {} (N = {:.3e} +- {:.1e}, theta in [{:.6}, {:.6}], drift {} per period)",
            c.integer,
            digits(c.kappa, 12),
            digits(c.energy, 12),
            c.rotation_number,
            c.error_estimate,
            c.theta_min,
            c.theta_max,
            digits(c.drift, 6)
        );
    }
    if v.holds.is_some() {
        let e = &v.evidence;
        println!(
            "  evidence: {} kappa-lines from {:.3e} to {:.0e}, {} energies per line, {} tori solved, N in [{:.6}, {:.6}]",
            e.kappa_lines,
            e.kappa_range[0],
            e.kappa_range[1],
            e.energies_per_line,
            e.components_solved,
            e.rotation_number_range[0],
            e.rotation_number_range[1]
        );
        for l in &e.limits {
            println!("    {l}");
        }
    }
}

/// `--resolution` as a count; what is not one (negative, a fraction, beyond 2^32) is refused
/// naming the range (the verdict's own check refuses the counts outside it).
fn resolution(text: &str) -> std::result::Result<usize, String> {
    let range = "must be a whole number between 8 and 4096 (32 and 4096 with --boundaries)";
    text.trim()
        .parse::<i128>()
        .ok()
        .and_then(|n| u32::try_from(n).ok())
        .map(|n| n as usize)
        .ok_or_else(|| range.to_string())
}

/// The census of a body other than the ellipsoid (`verdict --shape`): which integers N
/// reaches over its plane ([`verdict::census`]).
fn census(args: &VerdictArgs, body: &AnyBody) -> Result<()> {
    let options = verdict::CensusOptions {
        tol: args.tol,
        resolution: args.resolution,
    };
    let full = verdict::census_report(body, &options, &crate::stop::requested)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&full)?);
        return Ok(());
    }
    let report = &full.census;
    let parameters = body.shape_parameters();
    let named: Vec<String> = parameters
        .iter()
        .map(|(name, value)| format!("{name} = {}", show(*value)))
        .collect();
    println!(
        "{} {} (nu = {}, eta = {}): which integers N reaches over the (kappa, energy) plane",
        body.shape_name(),
        named.join(", "),
        show(args.nu),
        show(args.eta)
    );
    println!("  (the paper's hypothesis is the ellipsoid's: this is a census, not a verdict)");
    let list = |ks: &[i64]| -> String {
        if ks.is_empty() {
            "none".to_string()
        } else {
            ks.iter()
                .map(|k| k.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        }
    };
    println!(
        "  integers reached where the path runs away: {}",
        list(&report.integers)
    );
    let spans = |rs: &[[i64; 2]]| -> String {
        rs.iter()
            .map(|&[a, b]| match b - a {
                0 => a.to_string(),
                1 => format!("{a}, {b}"),
                _ => format!("{a} ... {b}"),
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !report.bracketed.is_empty() {
        println!(
            "  bracketed by samples of one family, no point confirmed: {}",
            spans(&report.bracketed)
        );
    }
    if !report.near_integers.is_empty() {
        println!(
            "  N within the tolerance of, with no sign change to prove it reaches them: {}",
            list(&report.near_integers)
        );
    }
    match report.unbounded_motion {
        Some(true) => {
            println!("  unbounded motion: yes, where N is an integer and the drift is not 0:")
        }
        _ => println!(
            "  unbounded motion: {}",
            report.evidence.undecided.as_deref().unwrap_or("not shown")
        ),
    }
    for c in &report.counterexamples {
        println!(
            "    N = {} at kappa = {}, energy = {} (component {}, theta in [{:.6}, {:.6}]): |drift| = {} +- {} a period",
            c.integer,
            digits(c.kappa, 10),
            digits(c.energy, 10),
            c.component,
            c.theta_min,
            c.theta_max,
            digits(c.drift, 6),
            digits(c.drift_error, 2)
        );
    }
    for r in &report.full_model_checks {
        println!(
            "    full equations, N = {} at kappa = {}: {} periods carry the centre of mass {} away, {} x |drift| = {} (relative gap {:.1e}{})",
            r.integer,
            digits(r.kappa, 6),
            r.periods,
            digits(r.distance, 8),
            r.periods,
            digits(r.expected, 8),
            r.relative_gap,
            if r.relative_gap > verdict::FULL_MODEL_GAP {
                ": beyond the full model's usual accuracy, which does not resolve this body at its tolerance"
            } else {
                ""
            }
        );
    }
    for l in &report.from_limits {
        println!(
            "  proved by a limit: N = {}: {}",
            spans(&[[l.lowest, l.highest]]),
            l.reason
        );
    }
    let h = &report.high_energy;
    println!(
        "  high energy: N_inf -> {} as lambda -> 0; min {} at lambda = {}; max {} at lambda = {}; sign changes at lambda = {:?} (error {})",
        digits(h.at_small_lambda, 10),
        digits(h.n_min, 10),
        digits(h.lambda_at_min, 6),
        digits(h.n_max, 10),
        digits(h.lambda_at_max, 6),
        h.zeros,
        digits(h.error, 2)
    );
    let e = &report.evidence;
    if e.kappa_lines == 0 {
        return Ok(());
    }
    println!(
        "  evidence: {} kappa-lines in [{}, {}], {} energies per line, {} components; N sampled in [{}, {}]; {} integer brackets, {} refinements failed",
        e.kappa_lines,
        show(e.kappa_range[0]),
        show(e.kappa_range[1]),
        e.energies_per_line,
        e.components_solved,
        digits(e.rotation_number_range[0], 6),
        digits(e.rotation_number_range[1], 6),
        e.integer_brackets,
        e.refinement_failures
    );
    Ok(())
}
