//! Command-line definitions (clap) and the glue from flags to the library.

use crate::progress::Reporter;
use anyhow::{Context, Result};
use clap::{ArgGroup, Args, Parser, Subcommand, ValueEnum};
use rubber_atlas::atlas::Shard;
use rubber_atlas::cell::{solve_cell, solve_component, CellOptions, CellResult, Method, Status};
use rubber_atlas::cf::AttrValue;
use rubber_atlas::critical::CriticalSet;
use rubber_atlas::error::AtlasError;
use rubber_atlas::resonance::{self, ResonanceOptions};
use rubber_atlas::scene::Scene;
use rubber_atlas::store::{check_output, write_table};
use rubber_atlas::sweep::{self, RunRequest};
use rubber_atlas::torus::EffectivePotential;
use rubber_atlas::trajectory::{self, Duration, Model, Start, StartAt};
use rubber_atlas::verdict::{self, VerdictOptions};
use rubber_atlas::EllipsoidBody;
use std::path::PathBuf;

/// `--version`: the package version and the git commit it was built from, marked `-dirty`
/// when the sources differed from that commit.
const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (",
    env!("RUBBER_ATLAS_GIT_COMMIT"),
    ")"
);

/// Atlases of the dynamics of a "rubber" ellipsoid of revolution rolling on a plane.
#[derive(Debug, Parser)]
#[command(
    name = "rubber-atlas",
    version = VERSION,
    about,
    long_about = None,
    arg_required_else_help = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// The critical set of one body (paper §4): diagram type, permanent rotations with their
    /// stability, equilibria, cusp, ε_min.
    Diagram(DiagramArgs),
    /// θ, ψ, φ, centre of mass and contact point over time, from the reduced or the full model.
    Trajectory(TrajectoryArgs),
    /// One cell (κ, ε): per component of the allowed set ω_θ, ω_ψ, the rotation number N, the
    /// drift |Δζ| and radius R, bounded or not, status and error estimates.
    Cell(CellArgs),
    /// Builds the atlas of a scene (TOML) into an HDF5 file that opens in xarray, with
    /// progress, resume after a crash, and shards for a cluster.
    Run(RunArgs),
    /// Joins the shard files of one scene (made with `run --shard I/N`) into one atlas.
    Merge(MergeArgs),
    /// The curves of the (κ, ε) plane on which a component's rotation number is P/Q, traced
    /// by continuation with the cell solver; with --fold, the fold κ_max of the curve of
    /// largest κ (N = P/Q, ∂N/∂ε = 0).
    Resonance(ResonanceArgs),
    /// The paper's boundedness hypothesis for one body over the whole (κ, ε) plane: its case,
    /// whether it holds, κ_max, counterexamples on integer resonances and the high-energy
    /// limit N∞(λ); with --boundaries, the β at which the verdict changes for one α.
    Verdict(VerdictArgs),
    /// Prints a completion script for a shell, e.g. `rubber-atlas completions bash >
    /// /etc/bash_completion.d/rubber-atlas`.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Prints the manual page (roff), e.g. `rubber-atlas man > rubber-atlas.1; man
    /// ./rubber-atlas.1`.
    Man,
}

#[derive(Debug, Args)]
pub struct VerdictArgs {
    /// α = a/b3: displacement of the centre of mass along the axis, 0 <= α < 1.
    #[arg(long, allow_hyphen_values = true)]
    pub alpha: f64,
    /// β = b1/b3 (not with --boundaries).
    #[arg(
        long,
        allow_hyphen_values = true,
        required_unless_present = "boundaries",
        conflicts_with = "boundaries"
    )]
    pub beta: Option<f64>,
    /// ν = i3/i1, 0 < ν <= 2.
    #[arg(long, allow_hyphen_values = true)]
    pub nu: f64,
    /// η = m b3²/i1 > 0.
    #[arg(long, allow_hyphen_values = true)]
    pub eta: f64,
    /// The β at which the verdict changes along β at this α, each by root-finding.
    #[arg(long)]
    pub boundaries: bool,
    /// Smallest β searched by --boundaries [default: 0.05].
    #[arg(long, allow_hyphen_values = true)]
    pub beta_min: Option<f64>,
    /// Largest β searched by --boundaries [default: 50].
    #[arg(long, allow_hyphen_values = true)]
    pub beta_max: Option<f64>,
    /// Log-spaced β of the scan behind --boundaries (the line β² = 1 + α is added)
    /// [default: 48].
    #[arg(long)]
    pub scan: Option<usize>,
    /// Tolerance of the cell solver (N at a counterexample equals the integer to this).
    #[arg(long, default_value_t = 1e-10, allow_hyphen_values = true)]
    pub tol: f64,
    /// κ-lines of each kind and energies per line of the sampling (doubling it halves the
    /// spacing).
    #[arg(long, default_value_t = 64)]
    pub resolution: usize,
    /// Print one JSON object (SPEC §4 contract).
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct ResonanceArgs {
    #[command(flatten)]
    pub shape: ShapeArgs,
    /// ν = i3/i1, 0 < ν <= 2.
    #[arg(long, allow_hyphen_values = true)]
    pub nu: f64,
    /// η = m b3²/i1 > 0.
    #[arg(long, allow_hyphen_values = true)]
    pub eta: f64,
    /// The rotation number of the curves: P/Q (e.g. 0, 1, -1/7) or a decimal.
    #[arg(long, value_name = "P/Q", allow_hyphen_values = true)]
    pub rotation_number: String,
    /// The window: smallest κ (> 0; N = 0 at κ = 0).
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    pub kappa_min: f64,
    /// The window: largest κ.
    #[arg(long, default_value_t = 2.0, allow_hyphen_values = true)]
    pub kappa_max: f64,
    /// The window: smallest ε [default: the lowest minimum of V over the window].
    #[arg(long, allow_hyphen_values = true)]
    pub energy_min: Option<f64>,
    /// The window: largest ε.
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    pub energy_max: f64,
    /// Rows of κ (and energies per row) of the seed scan; curves are also followed between
    /// rows, but a closed curve that crosses no row is missed.
    #[arg(long, default_value_t = 48)]
    pub grid: usize,
    /// Tolerance of the cell solver (N on the curve equals P/Q to this).
    #[arg(long, default_value_t = 1e-10, allow_hyphen_values = true)]
    pub tol: f64,
    /// Print the fold of the curve of largest κ as JSON {"kappa_max": …, "energy": …}.
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

#[derive(Debug, Args)]
pub struct RunArgs {
    /// The scene file (TOML; see atlas/*.toml).
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Output file [default: atlas/<name>.h5; with --shard I/N atlas/<name>.shard-I-of-N.h5].
    #[arg(long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    /// Worker threads [default: RAYON_NUM_THREADS if set, else every core].
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Continue an interrupted run of the same scene and output (finished units are kept).
    #[arg(long)]
    pub resume: bool,
    /// Overwrite an existing output and discard an interrupted run.
    #[arg(long)]
    pub force: bool,
    /// Bring the output up to date (as a Slurm task does): keep it if it was made from this
    /// scene by this build for this shard, continue an interrupted run of the same, and
    /// compute afresh (replacing) whatever is stale.
    #[arg(long, conflicts_with_all = ["force", "resume"])]
    pub update: bool,
    /// Print the output path the run would write (the default from the scene's name and
    /// --shard, or --out) and exit.
    #[arg(long)]
    pub print_out: bool,
    #[command(flatten)]
    pub limits: Limits,
    /// Compute part I of N of the grid (1 <= I <= N) into its own file.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// No progress and no summary.
    #[arg(long)]
    pub quiet: bool,
}

/// The size check of a command that may ask for more than the machine has.
#[derive(Debug, Args)]
pub struct Limits {
    /// Run even where the estimated memory or disk exceeds what this machine has free.
    #[arg(long)]
    pub allow_large: bool,
}

impl Limits {
    /// Refuses work whose estimated peak `memory` (over 80 % of what is available) or `disk`
    /// for `out` (over what is free there) exceeds the machine, in one line with both
    /// figures, the `remedy` and --allow-large; nothing with --allow-large.
    fn check(
        &self,
        memory: f64,
        disk: Option<f64>,
        out: Option<&std::path::Path>,
        remedy: &str,
    ) -> Result<()> {
        if self.allow_large {
            return Ok(());
        }
        let mut short = Vec::new();
        if let Some(free) = available_memory().filter(|&free| memory > 0.8 * free) {
            short.push(format!(
                "about {} of memory ({} available)",
                show_bytes(memory),
                show_bytes(free)
            ));
        }
        if let (Some(disk), Some(out)) = (disk, out) {
            if let Some(free) = free_disk(out).filter(|&free| disk > free) {
                short.push(format!(
                    "up to {} of disk ({} free there)",
                    show_bytes(disk),
                    show_bytes(free)
                ));
            }
        }
        if short.is_empty() {
            return Ok(());
        }
        Err(AtlasError::Atlas {
            path: out.map_or("the request".into(), |o| o.display().to_string()),
            reason: format!(
                "needs {}; {remedy}; --allow-large runs it anyway",
                short.join(" and ")
            ),
        }
        .into())
    }
}

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The shard files, all N of them, in any order.
    #[arg(value_name = "SHARDS", required = true)]
    pub shards: Vec<PathBuf>,
    /// The merged atlas.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Overwrite an existing output.
    #[arg(long)]
    pub force: bool,
    /// No summary.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Tanh-sinh quadrature between the turning points (fast).
    Quadrature,
    /// DOP853 over one θ-period with event location (the independent check).
    Ode,
}

/// Where on the level set: an energy, or an initial state θ(0), θ̇(0).
#[derive(Debug, Args)]
#[command(group(ArgGroup::new("start").required(true).args(["energy", "theta0"])))]
pub struct StartArgs {
    /// Energy ε (`cell`: every component; `trajectory`: start at the lower turning point of
    /// component --component with θ̇ = 0).
    #[arg(long, allow_hyphen_values = true)]
    pub energy: Option<f64>,
    /// Initial inclination θ(0) (`cell`: only the component that holds it).
    #[arg(long, allow_hyphen_values = true)]
    pub theta0: Option<f64>,
    /// Initial θ̇(0) (with --theta0) [default: 0].
    #[arg(long, requires = "theta0", allow_hyphen_values = true)]
    pub theta_dot0: Option<f64>,
}

impl StartArgs {
    /// The checked start at θ(0) = `theta0` with this θ̇(0), at F2 = `kappa`.
    fn at_theta0(&self, kappa: f64, theta0: f64) -> rubber_atlas::Result<Start> {
        let start = Start {
            kappa,
            theta0,
            theta_dot0: self.theta_dot0.unwrap_or(0.0),
        };
        start.check()?;
        Ok(start)
    }
}

#[derive(Debug, Args)]
pub struct CellArgs {
    #[command(flatten)]
    pub level: LevelArgs,
    #[command(flatten)]
    pub start: StartArgs,
    /// Accuracy: relative for T, ω, drift; absolute for N. 1e-15 <= TOL <= 0.1.
    #[arg(long, default_value_t = 1e-10, allow_hyphen_values = true)]
    pub tol: f64,
    /// How to compute the period integrals.
    #[arg(long, value_enum, default_value_t = MethodArg::Quadrature)]
    pub method: MethodArg,
    /// |N − round(N)| at or below this (or N's error estimate) counts as a resonance.
    #[arg(long, default_value_t = 1e-9, allow_hyphen_values = true)]
    pub resonance_tol: f64,
    /// Print one JSON object (keys of SPEC §3.1).
    #[arg(long)]
    pub json: bool,
}

/// α and β of the ellipsoid.
#[derive(Debug, Args)]
pub struct ShapeArgs {
    /// α = a/b3: displacement of the centre of mass along the axis, 0 <= α < 1.
    #[arg(long, allow_hyphen_values = true)]
    pub alpha: f64,
    /// β = b1/b3: < 1 prolate, > 1 oblate, 1 sphere.
    #[arg(long, allow_hyphen_values = true)]
    pub beta: f64,
}

/// The body (α, β, ν, η) and κ: what a level set of the reduced system needs besides ε.
#[derive(Debug, Args)]
pub struct LevelArgs {
    #[command(flatten)]
    pub shape: ShapeArgs,
    /// ν = i3/i1, 0 < ν <= 2.
    #[arg(long, allow_hyphen_values = true)]
    pub nu: f64,
    /// η = m b3²/i1 > 0.
    #[arg(long, allow_hyphen_values = true)]
    pub eta: f64,
    /// κ, the value of the integral F2 = J ω3.
    #[arg(long, allow_hyphen_values = true)]
    pub kappa: f64,
}

impl LevelArgs {
    /// The validated body.
    fn body(&self) -> Result<EllipsoidBody> {
        Ok(EllipsoidBody::ellipsoid(
            self.shape.alpha,
            self.shape.beta,
            self.nu,
            self.eta,
        )?)
    }
}

#[derive(Debug, Args)]
pub struct DiagramArgs {
    #[command(flatten)]
    pub shape: ShapeArgs,
    /// ν = i3/i1 (does not change the critical set; recorded in the output).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub nu: f64,
    /// η = m b3²/i1 (does not change the critical set; recorded in the output).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
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
    /// Samples of θ0 per half (θ0 < π/2, θ0 > π/2) of the fixed-point curves.
    #[arg(long, default_value_t = 2000)]
    pub samples: usize,
    #[command(flatten)]
    pub limits: Limits,
    /// Truncate the sampled curves at this κ.
    #[arg(long, default_value_t = 3.0, allow_hyphen_values = true)]
    pub kappa_max: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModelArg {
    /// The reduced system `eqsys` with its quadratures.
    Reduced,
    /// The full redundant system `eqred` with the kinematics.
    Full,
}

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("length").required(true).args(["periods", "t_end"])))]
pub struct TrajectoryArgs {
    #[command(flatten)]
    pub level: LevelArgs,
    #[command(flatten)]
    pub start: StartArgs,
    /// Which component of the level set (κ, ε) to start on, counted from the smallest θ
    /// (with --energy) [default: 0].
    #[arg(long, requires = "energy")]
    pub component: Option<usize>,
    /// Length in θ-periods of the starting component.
    #[arg(long, allow_hyphen_values = true)]
    pub periods: Option<f64>,
    /// Length in time units √(b3/g).
    #[arg(long, allow_hyphen_values = true)]
    pub t_end: Option<f64>,
    /// Number of output intervals (the file has SAMPLES + 1 rows).
    #[arg(long, default_value_t = 2000)]
    pub samples: usize,
    #[command(flatten)]
    pub limits: Limits,
    /// Relative and absolute tolerance of the DOP853 integrator.
    #[arg(long, default_value_t = 1e-12, allow_hyphen_values = true)]
    pub tol: f64,
    /// Which equations to integrate.
    #[arg(long, value_enum, default_value_t = ModelArg::Reduced)]
    pub model: ModelArg,
    /// Output file: .csv, .h5 or .hdf5.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Overwrite an existing --out file.
    #[arg(long)]
    pub force: bool,
}

/// Runs one parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Diagram(args) => diagram(args),
        Command::Trajectory(args) => trajectory(args),
        Command::Cell(args) => cell(args),
        Command::Run(args) => run_scene(args),
        Command::Merge(args) => merge(args),
        Command::Resonance(args) => resonance(args),
        Command::Verdict(args) => verdict(args),
        Command::Completions { shell } => {
            let mut command = <Cli as clap::CommandFactory>::command();
            clap_complete::generate(shell, &mut command, "rubber-atlas", &mut std::io::stdout());
            Ok(())
        }
        Command::Man => {
            let command = <Cli as clap::CommandFactory>::command();
            clap_mangen::Man::new(command)
                .render(&mut std::io::stdout())
                .context("cannot write the manual page")?;
            Ok(())
        }
    }
}

fn verdict(args: VerdictArgs) -> Result<()> {
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
        let found = verdict::boundaries(
            args.alpha,
            args.nu,
            args.eta,
            &verdict::BoundaryOptions {
                beta_min: args.beta_min.unwrap_or(defaults.beta_min),
                beta_max: args.beta_max.unwrap_or(defaults.beta_max),
                scan: args.scan.unwrap_or(defaults.scan),
                verdict: options,
            },
        )?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&found)?);
        } else {
            println!(
                "alpha = {} (nu = {}, eta = {}): the verdict along beta in [{}, {}]",
                found.alpha, found.nu, found.eta, found.beta_range[0], found.beta_range[1]
            );
            let side = |c: verdict::Case, h: Option<bool>| match h {
                None => "not covered".to_string(),
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
        }
        return Ok(());
    }
    let beta = args.beta.unwrap_or(1.0);
    let body = EllipsoidBody::ellipsoid(args.alpha, beta, args.nu, args.eta)?;
    let options = VerdictOptions {
        coarse_first: true,
        ..options
    };
    let v = verdict::verdict(&body, &options)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    print_verdict(&v);
    Ok(())
}

fn print_verdict(v: &verdict::Verdict) {
    use verdict::Case;
    println!(
        "ellipsoid alpha = {}, beta = {} (nu = {}, eta = {}): diagram type ({})",
        v.alpha,
        v.beta,
        v.nu,
        v.eta,
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
        println!("  kappa_max = {k:.10} (+- {e:.1e}), the fold of the N = 0 curve beside sigma_u");
    }
    let h = &v.high_energy;
    println!(
        "  high energy: N_inf(lambda) ~ {:.6e} lambda at lambda -> 0; min {:.10} at lambda = {:.6}; max {:.10} at lambda = {:.6}",
        h.slope,
        h.n_min,
        h.lambda_at_min,
        h.n_max,
        h.lambda_at_max
    );
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
            "  counterexample: N = {} at kappa = {:.12}, energy = {:.12} (N = {:.3e} +- {:.1e}, theta in [{:.6}, {:.6}], drift {:.6} per period)",
            c.integer,
            c.kappa,
            c.energy,
            c.rotation_number,
            c.error_estimate,
            c.theta_min,
            c.theta_max,
            c.drift
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

/// P/Q or a decimal.
fn parse_rotation_number(text: &str) -> Result<f64> {
    let bad = || AtlasError::Atlas {
        path: format!("--rotation-number {text}"),
        reason: "expected P/Q with whole numbers P and Q != 0, or a number".into(),
    };
    let value = match text.split_once('/') {
        Some((p, q)) => {
            let p: i64 = p.trim().parse().map_err(|_| bad())?;
            let q: i64 = q.trim().parse().map_err(|_| bad())?;
            if q == 0 {
                return Err(bad().into());
            }
            p as f64 / q as f64
        }
        None => text.trim().parse::<f64>().map_err(|_| bad())?,
    };
    if !value.is_finite() {
        return Err(bad().into());
    }
    Ok(value)
}

fn resonance(args: ResonanceArgs) -> Result<()> {
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
    let body = EllipsoidBody::ellipsoid(args.shape.alpha, args.shape.beta, args.nu, args.eta)?;
    let target = parse_rotation_number(&args.rotation_number)?;
    let options = ResonanceOptions::window(
        &body,
        target,
        (args.kappa_min, args.kappa_max),
        args.energy_min,
        args.energy_max,
        args.grid,
        args.tol,
    );
    let header = serde_json::json!({
        "alpha": args.shape.alpha,
        "beta": args.shape.beta,
        "nu": args.nu,
        "eta": args.eta,
        "rotation_number": target,
        "kappa_window": [options.kappa.0, options.kappa.1],
        "energy_window": [options.energy.0, options.energy.1],
        "tolerance": args.tol,
    });
    if args.fold {
        let fold = resonance::fold(&body, &options)?;
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
                     through kappa_max (widen --kappa-max)"
                );
            }
        }
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    let curves = resonance::trace_curves(&body, &options)?;
    if args.json {
        let mut value = header;
        value["curves"] = serde_json::to_value(&curves)?;
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    if let Some(out) = &args.out {
        let mut table = rubber_atlas::table::resonance(&curves);
        table.attributes.extend(table_attributes(&[
            ("alpha", AttrValue::Number(args.shape.alpha)),
            ("beta", AttrValue::Number(args.shape.beta)),
            ("nu", AttrValue::Number(args.nu)),
            ("eta", AttrValue::Number(args.eta)),
            ("rotation_number", AttrValue::Number(target)),
            ("tolerance", AttrValue::Number(args.tol)),
            ("header_json", AttrValue::Text(header.to_string())),
        ]));
        write_table(out, &table)?;
        println!(
            "wrote {} curves ({} points) to {}",
            curves.len(),
            curves.iter().map(|c| c.points.len()).sum::<usize>(),
            out.display()
        );
        return Ok(());
    }
    println!(
        "N = {target} for alpha={} beta={} nu={} eta={}: {} curve(s) in kappa [{}, {}], energy [{:.6}, {}]",
        args.shape.alpha, args.shape.beta, args.nu, args.eta, curves.len(),
        options.kappa.0, options.kappa.1, options.energy.0, options.energy.1
    );
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
            "[{i}] {} points{}, well theta = {:.6}, kappa in [{kmin:.6}, {kmax:.6}], energy in [{emin:.6}, {emax:.6}]",
            c.points.len(),
            if c.closed { " (closed)" } else { "" },
            c.points[0].well
        );
    }
    Ok(())
}

/// The attributes a command adds to the atlases it writes: its command line, the time, and
/// the CF `history`.
fn invocation_attributes() -> Vec<(String, AttrValue)> {
    let command = command_line();
    vec![
        ("command_line".into(), AttrValue::Text(command.clone())),
        (
            "created".into(),
            AttrValue::Text(rubber_atlas::cf::utc_now()),
        ),
        (
            "history".into(),
            AttrValue::Text(rubber_atlas::cf::history(&command)),
        ),
    ]
}

/// The root attributes of a table: provenance (program, commit, history, command line)
/// and `own`, the command's parameters (numbers as numbers).
fn table_attributes(own: &[(&str, AttrValue)]) -> Vec<(String, AttrValue)> {
    let command = command_line();
    let mut attributes = rubber_atlas::store::provenance(&command);
    attributes.push(("command_line".into(), AttrValue::Text(command)));
    attributes.extend(own.iter().map(|(k, v)| (k.to_string(), v.clone())));
    attributes
}

fn run_scene(args: RunArgs) -> Result<()> {
    let scene = Scene::from_file(&args.scene)?;
    let shard = match &args.shard {
        Some(text) => Shard::parse(text)?,
        None => Shard::WHOLE,
    };
    // A shard count that does not tile the grid is refused at once (also by --print-out,
    // which submit.sh calls before anything is queued).
    shard.check_against(scene.shape())?;
    let out = args.out.clone().unwrap_or_else(|| {
        if shard == Shard::WHOLE {
            PathBuf::from(format!("atlas/{}.h5", scene.name))
        } else {
            PathBuf::from(format!(
                "atlas/{}.shard-{}-of-{}.h5",
                scene.name, shard.index, shard.count
            ))
        }
    });
    if args.print_out {
        println!("{}", out.display());
        return Ok(());
    }
    // Before any work: never a directory, device, symlink or the scene itself.
    check_output(
        &out,
        args.force || args.resume || args.update,
        &[&args.scene],
        &ATLAS_EXTENSIONS,
    )?;
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(AtlasError::Atlas {
                path: out.display().to_string(),
                reason: format!("the directory {} does not exist", parent.display()),
            }
            .into());
        }
    }
    // --threads, else RAYON_NUM_THREADS (as rayon itself reads it), else every core.
    let from_env = std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.trim().parse::<usize>().ok())
        .filter(|&n| n > 0);
    let threads = match args.threads.or(from_env) {
        Some(0) => {
            return Err(AtlasError::Atlas {
                path: "--threads 0".into(),
                reason: "needs at least one thread".into(),
            }
            .into())
        }
        // More threads than cores only add overhead: capped at the cores.
        Some(n) => n.min(std::thread::available_parallelism().map_or(1, |c| c.get())),
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    // Before anything is allocated: a grid the machine cannot hold is refused in one line.
    let need = sweep::footprint(&scene, shard, threads);
    args.limits.check(
        need.memory_bytes,
        Some(need.disk_bytes),
        Some(&out),
        &format!(
            "the run has {:.3e} cells: {}use fewer kappa or energy points",
            need.cells,
            shards_to_fit(&need)
        ),
    )?;
    // The global pool, so that the run's serial parts (file creation, writing) stay on the
    // main thread: on a pool thread glibc grows that thread's heap a page at a time, and
    // creating the HDF5 file took 7 ms of mprotect calls instead of 1.
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .context("cannot start the worker threads")?;
    let request = RunRequest {
        out: out.clone(),
        resume: args.resume,
        force: args.force,
        update: args.update,
        shard,
        attributes: invocation_attributes(),
    };
    // The command that continues this run, quoted for a POSIX shell.
    let shard_arg = match &args.shard {
        Some(text) => format!(" --shard {}", shell_quote(text)),
        None => String::new(),
    };
    let resume = format!(
        "rubber-atlas run {}{shard_arg} --out {} --resume",
        shell_quote(&args.scene.display().to_string()),
        shell_quote(&out.display().to_string()),
    );
    crate::stop::install(&resume).context("cannot install the SIGINT and SIGTERM handlers")?;
    let reporter = Reporter::new(args.quiet, &scene.name);
    let summary = match sweep::run(&scene, &request, &reporter) {
        Err(AtlasError::Interrupted { done, total, .. }) => {
            reporter.finish();
            let (signal, status) = crate::stop::received();
            eprintln!(
                "rubber-atlas: stopped by {signal} with {done} of {total} cells computed and kept in {}; continue with: {resume}",
                rubber_atlas::store::journal::Journal::dir_for(&out).display(),
            );
            std::process::exit(i32::from(status));
        }
        result => result?,
    };
    reporter.finish();
    if summary.up_to_date {
        if !args.quiet {
            println!(
                "{} is complete and current (this scene, this build); nothing to do",
                out.display()
            );
        }
        return Ok(());
    }
    if !args.quiet {
        print_summary(&summary, &out, threads);
    }
    Ok(())
}

/// Bytes as a person reads them, one format throughout: 1.5 GB, 310.0 MB.
fn show_bytes(bytes: f64) -> String {
    let units = [("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)];
    match units.iter().find(|(_, size)| bytes >= *size) {
        Some((name, size)) => format!("{:.1} {name}", bytes / size),
        None => format!("{bytes:.0} B"),
    }
}

/// Memory the kernel could give this process now (MemAvailable), if it says.
fn available_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Free space for an unprivileged user in the folder that will hold `out`.
fn free_disk(out: &std::path::Path) -> Option<f64> {
    use std::os::unix::ffi::OsStrExt;
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => std::path::Path::new("."),
    };
    let c_path = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
    // SAFETY: statvfs fills the zeroed struct from a valid NUL-terminated path.
    let mut stat: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(c_path.as_ptr(), &mut stat) } != 0 {
        return None;
    }
    Some(stat.f_bavail as f64 * stat.f_frsize as f64)
}

/// The shards a run would need for its largest slice to fit in half the available memory,
/// as a phrase for the refusal ("" when one machine would do).
fn shards_to_fit(need: &sweep::Footprint) -> String {
    let shards = available_memory().map_or(1.0, |free| (need.memory_bytes / (0.5 * free)).ceil());
    if shards > 1.0 {
        format!("split it with --shard I/N (N >= {shards:.0}) across machines, or ")
    } else {
        String::new()
    }
}

fn merge(args: MergeArgs) -> Result<()> {
    let inputs: Vec<&std::path::Path> = args.shards.iter().map(|p| p.as_path()).collect();
    check_output(&args.out, args.force, &inputs, &ATLAS_EXTENSIONS)?;
    let summary = sweep::merge(
        &args.shards,
        &args.out,
        args.force,
        &invocation_attributes(),
    )?;
    if !args.quiet {
        println!(
            "merged {} shards into {} ({} cells, {} components) in {:.2} s",
            args.shards.len(),
            args.out.display(),
            summary.cells,
            summary.components,
            summary.seconds
        );
    }
    Ok(())
}

fn print_summary(summary: &sweep::Summary, out: &std::path::Path, threads: usize) {
    let [ok, no_motion, failed] = summary.cells_by_status;
    let [c_ok, c_tol, c_fixed, c_sep, c_limit] = summary.components_by_status;
    let rate = summary.cells_computed as f64 / summary.seconds.max(1e-9);
    println!("wrote {}", out.display());
    println!(
        "cells: {} (with motion {ok}, no motion {no_motion}, failed {failed}); components: {}",
        summary.cells, summary.components
    );
    println!(
        "components by status: ok {c_ok}, tolerance_not_reached {c_tol}, fixed_point {c_fixed}, \
         separatrix {c_sep}, high_energy_limit {c_limit}"
    );
    println!(
        "units: {} ({} resumed from an interrupted run, {} computed now)",
        summary.units,
        summary.units_resumed,
        summary.units - summary.units_resumed
    );
    println!(
        "time: {:.2} s on {threads} thread(s), {} cells computed, {rate:.0} cells per second",
        summary.seconds, summary.cells_computed
    );
}

/// Refuses options that the chosen start would silently ignore (clap's `requires` cannot see
/// this through the flattened start group).
fn check_start(start: &StartArgs, component: Option<usize>) -> Result<()> {
    let refuse = |reason: &str| -> Result<()> {
        Err(AtlasError::Atlas {
            path: "options".into(),
            reason: reason.into(),
        }
        .into())
    };
    if start.theta_dot0.is_some() && start.theta0.is_none() {
        return refuse("--theta-dot0 goes with --theta0 (with --energy the start is at rest at a turning point)");
    }
    if component.is_some() && start.energy.is_none() {
        return refuse(
            "--component goes with --energy (with --theta0 the start chooses the component)",
        );
    }
    Ok(())
}

fn cell(args: CellArgs) -> Result<()> {
    check_start(&args.start, None)?;
    let body = args.level.body()?;
    let options = CellOptions {
        tol: args.tol,
        method: match args.method {
            MethodArg::Quadrature => Method::Quadrature,
            MethodArg::Ode => Method::Ode,
        },
        drift: true,
        resonance_tol: args.resonance_tol,
    };
    let result = match (args.start.energy, args.start.theta0) {
        (Some(e), _) => solve_cell(&body, args.level.kappa, e, &options)?,
        (None, Some(t)) => {
            // Only the component that holds θ(0).
            let start = args.start.at_theta0(args.level.kappa, t)?;
            options.validate()?;
            let potential = EffectivePotential::new(&body, start.kappa);
            let energy = start.checked_energy(&body)?;
            let component = start.component_in(&potential)?;
            CellResult {
                kappa: start.kappa,
                energy,
                status: Status::Ok,
                components: vec![solve_component(&potential, energy, &component, &options)?],
            }
        }
        (None, None) => unreachable!("clap requires --energy or --theta0"),
    };
    let energy = result.energy;
    if args.json {
        let value = serde_json::json!({
            "alpha": args.level.shape.alpha,
            "beta": args.level.shape.beta,
            "nu": args.level.nu,
            "eta": args.level.eta,
            "kappa": args.level.kappa,
            "energy": energy,
            "tolerance": args.tol,
            "method": options.method,
            "status": result.status,
            "components": result.components,
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    println!(
        "cell alpha={} beta={} nu={} eta={} kappa={} energy={} ({}, tol {:e}): {}",
        args.level.shape.alpha,
        args.level.shape.beta,
        args.level.nu,
        args.level.eta,
        args.level.kappa,
        energy,
        json_name(&options.method),
        args.tol,
        if result.components.is_empty() {
            "no motion (energy below the minimum of V)".to_string()
        } else {
            format!("{} component(s)", result.components.len())
        }
    );
    for (i, c) in result.components.iter().enumerate() {
        println!(
            "[{i}] {} on [{:.12}, {:.12}], status {}",
            json_name(&c.motion),
            c.theta_min,
            c.theta_max,
            json_name(&c.status)
        );
        let rows = [
            ("period T", c.period, c.errors.period),
            ("omega_theta", c.omega_theta, c.errors.omega_theta),
            ("omega_psi", c.omega_psi, c.errors.omega_psi),
            (
                "rotation number N",
                c.rotation_number,
                c.errors.rotation_number,
            ),
            ("drift |dzeta|", c.drift, c.errors.drift),
            ("drift radius R", c.drift_radius, c.errors.drift_radius),
        ];
        for (name, value, error) in rows {
            println!("    {name:<18} {value:>22.15e}  ± {error:.1e}");
        }
        match c.bounded {
            Some(b) => println!("    bounded            {b}"),
            None => println!("    bounded            (not computed)"),
        }
    }
    Ok(())
}

/// `text` as one word for a POSIX shell: as it is when it needs no quoting, else in single
/// quotes (a quote inside as '\'').
fn shell_quote(text: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_-./=:,+@%".contains(c);
    if !text.is_empty() && text.chars().all(plain) {
        text.to_string()
    } else {
        format!("'{}'", text.replace('\'', "'\\''"))
    }
}

/// The name a value has in the JSON output (`ok`, `libration`, `quadrature`), so that the
/// text output uses the same words.
fn json_name<T: serde::Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(name)) => name,
        Ok(other) => other.to_string(),
        Err(_) => String::from("?"),
    }
}

fn command_line() -> String {
    std::env::args().collect::<Vec<_>>().join(" ")
}

/// Tables (`diagram`, `trajectory`, `resonance`).
const TABLE_EXTENSIONS: [&str; 3] = ["csv", "h5", "hdf5"];
/// Atlases (`run`, `merge`).
const ATLAS_EXTENSIONS: [&str; 2] = ["h5", "hdf5"];

fn diagram(args: DiagramArgs) -> Result<()> {
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
        "use fewer --samples",
    )?;
    let body = EllipsoidBody::ellipsoid(args.shape.alpha, args.shape.beta, args.nu, args.eta)?;
    let set = CriticalSet::of(&body, args.samples, args.kappa_max)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&set)?);
        return Ok(());
    }
    if let Some(out) = &args.out {
        write_diagram(out, &set)?;
        eprintln!(
            "wrote {} points on {} branches to {}",
            set.branches.iter().map(|b| b.points.len()).sum::<usize>(),
            set.branches.len(),
            out.display()
        );
    }
    print_diagram(&set);
    Ok(())
}

fn print_diagram(set: &CriticalSet) {
    println!(
        "ellipsoid alpha = {}, beta = {} (nu = {}, eta = {}): diagram type ({})",
        set.alpha,
        set.beta,
        set.nu,
        set.eta,
        set.diagram_type.label()
    );
    println!(
        "  eps_min (roll over the top at kappa = 0) = {:.12}",
        set.energy_min
    );
    if let Some(t) = set.theta_star {
        println!("  inclined equilibrium theta* = {t:.12}");
    }
    for e in &set.equilibria {
        println!(
            "  equilibrium {:<10} theta = {:.12}  eps = {:.12}  {}{}",
            e.name,
            e.theta,
            e.energy,
            if e.stable { "stable" } else { "unstable" },
            if e.isolated { ", isolated" } else { "" }
        );
    }
    if let Some(c) = &set.cusp {
        println!(
            "  cusp theta_c = {:.12}  kappa_c = {:.12}  eps_c = {:.12}",
            c.theta, c.kappa, c.energy
        );
    }
    if let Some(k) = set.kappa_c_equator {
        println!("  equator sigma_pi2 stable for |kappa| > {k:.12}");
    }
    for b in &set.branches {
        let bottom = b
            .rotation_number_range
            .map(|[lo, hi]| format!("  N at the bottom in [{lo:.6}, {hi:.6}]"))
            .unwrap_or_default();
        println!(
            "  branch {:<10} {:<8} theta0 in [{:.6}, {:.6}]  kappa in [{:.6}, {:.6}]  eps in [{:.6}, {:.6}]{bottom}",
            b.name,
            if b.stable { "stable" } else { "unstable" },
            b.theta0_range[0],
            b.theta0_range[1],
            b.kappa_range[0],
            b.kappa_range[1],
            b.energy_range[0],
            b.energy_range[1]
        );
    }
}

fn write_diagram(out: &std::path::Path, set: &CriticalSet) -> Result<()> {
    let mut table = rubber_atlas::table::diagram(set);
    table.attributes.extend(table_attributes(&[
        ("alpha", AttrValue::Number(set.alpha)),
        ("beta", AttrValue::Number(set.beta)),
        ("nu", AttrValue::Number(set.nu)),
        ("eta", AttrValue::Number(set.eta)),
        (
            "critical_set_json",
            AttrValue::Text(serde_json::to_string(set)?),
        ),
    ]));
    write_table(out, &table).with_context(|| {
        format!(
            "writing the diagram of alpha = {}, beta = {}",
            set.alpha, set.beta
        )
    })?;
    Ok(())
}

fn trajectory(args: TrajectoryArgs) -> Result<()> {
    check_start(&args.start, args.component)?;
    check_output(&args.out, args.force, &[], &TABLE_EXTENSIONS)?;
    let body = args.level.body()?;
    if args.samples == 0 {
        return Err(AtlasError::InvalidParameter {
            name: "samples",
            value: 0.0,
            reason: "must be >= 1",
        }
        .into());
    }
    // Measured: 135 bytes of memory per sample at the peak; a CSV row of 10 columns is
    // under 250 bytes.
    let rows = args.samples as f64 + 1.0;
    args.limits.check(
        160.0 * rows,
        Some(250.0 * rows),
        Some(&args.out),
        "use fewer --samples",
    )?;
    let model = match args.model {
        ModelArg::Reduced => Model::Reduced,
        ModelArg::Full => Model::Full,
    };
    let request = trajectory::Request {
        kappa: args.level.kappa,
        start: match (args.start.energy, args.start.theta0) {
            (Some(energy), None) => StartAt::Energy {
                energy,
                component: args.component.unwrap_or(0),
            },
            (None, Some(theta0)) => StartAt::Angle {
                theta0,
                theta_dot0: args.start.theta_dot0.unwrap_or(0.0),
            },
            _ => unreachable!("clap requires exactly one of --energy, --theta0"),
        },
        duration: match (args.periods, args.t_end) {
            (Some(k), None) => Duration::Periods(k),
            (None, Some(t)) => Duration::Until(t),
            _ => unreachable!("clap requires exactly one of --periods, --t-end"),
        },
        samples: args.samples,
        model,
        tol: args.tol,
    };
    let (start, traj) = request.run(&body)?;
    let (tol, t_end) = (args.tol, traj.t.last().copied().unwrap_or(0.0));
    let mut table = rubber_atlas::table::trajectory(&traj);
    table.attributes.extend(table_attributes(&[
        ("model", AttrValue::Text(json_name(&model))),
        ("alpha", AttrValue::Number(args.level.shape.alpha)),
        ("beta", AttrValue::Number(args.level.shape.beta)),
        ("nu", AttrValue::Number(args.level.nu)),
        ("eta", AttrValue::Number(args.level.eta)),
        ("kappa", AttrValue::Number(start.kappa)),
        ("energy", AttrValue::Number(start.energy(&body))),
        ("theta0", AttrValue::Number(start.theta0)),
        ("theta_dot0", AttrValue::Number(start.theta_dot0)),
        ("tolerance", AttrValue::Number(tol)),
    ]));
    write_table(&args.out, &table)?;
    eprintln!(
        "wrote {} samples over t in [0, {}] ({} model) to {}",
        traj.t.len(),
        t_end,
        json_name(&model),
        args.out.display()
    );
    Ok(())
}
