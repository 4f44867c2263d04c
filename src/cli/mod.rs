//! Command-line definitions (clap) and the glue from flags to the library: the shared
//! arguments and helpers here, one module per command beside it. The science, the files'
//! contents and the tables live in the library.

mod cell;
mod diagram;
mod merge;
mod resonance;
mod run;
mod trajectory;
mod verdict;

use anyhow::{Context, Result};
use clap::{ArgGroup, Args, Parser, Subcommand, ValueEnum};
use rubber_atlas::cf::AttrValue;
use rubber_atlas::error::{show, show_digits as digits, AtlasError};
use rubber_atlas::machine::{disk_short, memory_short};
use rubber_atlas::trajectory::Start;
use rubber_atlas::{AnyBody, EdgedKind};

use cell::CellArgs;
use diagram::DiagramArgs;
use merge::MergeArgs;
use resonance::ResonanceArgs;
use run::RunArgs;
use trajectory::TrajectoryArgs;
use verdict::VerdictArgs;

/// `--version`: the package version and the git commit it was built from, marked `-dirty`
/// when the sources differed from that commit.
pub(crate) const VERSION: &str = concat!(
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
    #[command(after_long_help = run::SCENE_FORMAT)]
    Run(RunArgs),
    /// Joins the shard files of one scene (made with `run --shard I/N`) into one atlas.
    Merge(MergeArgs),
    /// The curves of the (κ, ε) plane on which a component's rotation number is P/Q, traced
    /// by continuation with the cell solver; with --fold, the fold κ_max of the curve of
    /// largest κ (N = P/Q, ∂N/∂ε = 0).
    Resonance(ResonanceArgs),
    /// The paper's boundedness hypothesis for one body over the whole (κ, ε) plane: its case,
    /// whether it holds, κ_max, counterexamples on integer resonances and the high-energy
    /// limit N∞(λ); with --boundaries, the β at which the verdict changes for one α; with
    /// --shape (a disk, a cut ball, a profile), which integers N reaches over its plane.
    Verdict(VerdictArgs),
    /// Prints a completion script for a shell, e.g. `rubber-atlas completions bash >
    /// /etc/bash_completion.d/rubber-atlas`.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Prints a manual page (roff): the program's, or a command's, e.g. `rubber-atlas man run
    /// > rubber-atlas-run.1; man ./rubber-atlas-run.1`; with --dir, writes every page there.
    Man {
        /// The command whose page to print (the program's page without it).
        #[arg(value_name = "COMMAND")]
        command: Option<String>,
        /// Write rubber-atlas.1 and rubber-atlas-<command>.1 for every command into this
        /// folder instead (e.g. /usr/local/share/man/man1).
        #[arg(long, value_name = "DIR", conflicts_with = "command")]
        dir: Option<std::path::PathBuf>,
        /// Replace pages that exist in --dir (never a link, a folder or a device there).
        #[arg(long, requires = "dir")]
        force: bool,
    },
}

/// The size check of a command that may ask for more than the machine has.
#[derive(Debug, Args)]
pub struct Limits {
    /// Run even where the estimated memory or disk exceeds what this machine has free, or a
    /// trajectory needs more than 1e9 integrator steps (some 40 minutes).
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
        remedy: &dyn Fn() -> String,
    ) -> Result<()> {
        if self.allow_large {
            return Ok(());
        }
        let short: Vec<String> = memory_short(memory)
            .into_iter()
            .chain(disk.zip(out).and_then(|(disk, out)| disk_short(disk, out)))
            .collect();
        if short.is_empty() {
            return Ok(());
        }
        Err(AtlasError::Atlas {
            path: out.map_or("the request".into(), |o| o.display().to_string()),
            reason: format!(
                "needs {}; {}; --allow-large runs it anyway",
                short.join(" and "),
                remedy()
            ),
        }
        .into())
    }
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
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub energy: Option<f64>,
    /// Initial inclination θ(0) (`cell`: only the component that holds it).
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub theta0: Option<f64>,
    /// Initial θ̇(0) (with --theta0) [default: 0].
    #[arg(value_parser = number, long, requires = "theta0", allow_hyphen_values = true)]
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

/// α and β of the ellipsoid.
#[derive(Debug, Args)]
pub struct ShapeArgs {
    /// α = a/b3: displacement of the centre of mass along the axis, -1 < α < 1 (α < 0 is the
    /// mirror image θ -> π - θ).
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub alpha: f64,
    /// β = b1/b3: < 1 prolate, > 1 oblate, 1 sphere.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub beta: f64,
}

/// The body's shape by name (docs/bodies.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ShapeKindArg {
    /// The ellipsoid of revolution (α, β): the paper's body.
    Ellipsoid,
    /// A thin disk rolling on its rim (α).
    Disk,
    /// A ball cut by the plane z = −h, rolling on its sphere or on the cut's edge (α, cut).
    #[value(name = "truncated_ball")]
    TruncatedBall,
    /// A ball cut by z = ±h, rolling on its sphere or on either edge (α, cut).
    Wheel,
    /// A body of your own: the arc spline through a table of its meridian's points
    /// (--profile FILE, α the centre of mass's height on the axis).
    Profile,
}

/// The shape of the body of `cell` and `trajectory`: the ellipsoid (the default) or an edged
/// body, with its parameters.
#[derive(Debug, Args)]
pub struct BodyShapeArgs {
    /// The body: ellipsoid (--alpha, --beta), disk (--alpha), truncated_ball or wheel
    /// (--alpha, --cut), profile (--alpha, --profile); docs/bodies.md.
    #[arg(long, value_enum, default_value_t = ShapeKindArg::Ellipsoid)]
    pub shape: ShapeKindArg,
    /// α: the centre of mass at α e3 from the body's centre (the ellipsoid's, in units of
    /// b3; the ball's or the disk's, in units of its radius); -1 < α < 1 but for the disk; a
    /// profile's: the height z = α on the axis, strictly between its poles.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub alpha: f64,
    /// β = b1/b3 of the ellipsoid (required for it): < 1 prolate, > 1 oblate, 1 sphere.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub beta: Option<f64>,
    /// h of the cut balls, in units of the ball's radius: the plane z = -h (truncated_ball,
    /// -1 < h < 1) or the planes z = ±h (wheel, 0 < h < 1).
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub cut: Option<f64>,
    /// The meridian of --shape profile: a text file of points `rho z` or `rho z edge` (edge 1
    /// at a sharp edge), one a line, from one pole (rho = 0) to the other; docs/bodies.md.
    #[arg(long, value_name = "FILE")]
    pub profile: Option<std::path::PathBuf>,
}

impl BodyShapeArgs {
    /// The validated body with mass parameters ν, η; a parameter the shape does not take,
    /// or one it needs and was not given, is refused in one line.
    pub fn body(&self, nu: f64, eta: f64) -> Result<AnyBody> {
        let refuse = |shape: &str, what: &str| -> Result<AnyBody> {
            Err(AtlasError::Atlas {
                path: "options".into(),
                reason: format!("--shape {shape}: {what}"),
            }
            .into())
        };
        let kind = match (self.shape, &self.profile) {
            (ShapeKindArg::Profile, None) => {
                return refuse(
                    "profile",
                    "--profile FILE is required (the meridian's points)",
                )
            }
            (ShapeKindArg::Profile, Some(path)) => Some(EdgedKind::Profile(read_profile(path)?)),
            (other, Some(_)) => {
                let name = other.to_possible_value().map(|v| v.get_name().to_string());
                return refuse(
                    &name.unwrap_or_default(),
                    "takes no --profile (only --shape profile does)",
                );
            }
            (ShapeKindArg::Ellipsoid, None) => None,
            (ShapeKindArg::Disk, None) => Some(EdgedKind::Disk),
            (ShapeKindArg::TruncatedBall, None) => Some(EdgedKind::TruncatedBall),
            (ShapeKindArg::Wheel, None) => Some(EdgedKind::Wheel),
        };
        let shape = kind.map_or("ellipsoid", |k| k.name());
        let refuse = |what: &str| refuse(shape, what);
        // β for the ellipsoid, the cut for the cut balls, nothing for the disk.
        let second = match (kind, self.beta, self.cut) {
            (None, None, _) => return refuse("--beta is required"),
            (None, Some(_), Some(_))
            | (Some(EdgedKind::Disk | EdgedKind::Profile(_)), _, Some(_)) => {
                return refuse("takes no --cut (only truncated_ball and wheel do)")
            }
            (None, Some(beta), None) => beta,
            (Some(_), Some(_), _) => return refuse("takes no --beta (only the ellipsoid does)"),
            (Some(EdgedKind::Disk | EdgedKind::Profile(_)), None, None) => 0.0,
            (Some(_), None, None) => return refuse("--cut is required"),
            (Some(_), None, Some(cut)) => cut,
        };
        Ok(AnyBody::new(kind, self.alpha, second, nu, eta)?)
    }
}

/// The profile in the table file `path` (--profile), refused in one line naming the file.
fn read_profile(path: &std::path::Path) -> Result<&'static rubber_atlas::Profile> {
    let fail = |reason: String| AtlasError::Atlas {
        path: path.display().to_string(),
        reason,
    };
    let text = rubber_atlas::scene::read_small_text(path, "a table of points").map_err(fail)?;
    let rows = rubber_atlas::body::parse_profile_table(&text).map_err(|e| fail(e.to_string()))?;
    Ok(rubber_atlas::Profile::from_points(&rows).map_err(|e| fail(e.to_string()))?)
}

/// The body (shape, ν, η) and κ: what a level set of the reduced system needs besides ε.
#[derive(Debug, Args)]
pub struct LevelArgs {
    #[command(flatten)]
    pub shape: BodyShapeArgs,
    /// ν = i3/i1, 0 < ν <= 2.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub nu: f64,
    /// η = m b3²/i1 > 0.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub eta: f64,
    /// κ, the value of the integral F2 = J ω3.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub kappa: f64,
}

impl LevelArgs {
    /// The validated body.
    fn body(&self) -> Result<AnyBody> {
        self.shape.body(self.nu, self.eta)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModelArg {
    /// The reduced system `eqsys` with its quadratures.
    Reduced,
    /// The full redundant system `eqred` with the kinematics.
    Full,
}

/// The body as the outputs name it: the ellipsoid's (α, β) as they always were; another
/// shape's name first, then its parameters.
fn body_fields(body: &AnyBody) -> Vec<(&'static str, AttrValue)> {
    let mut fields = Vec::new();
    if !matches!(body, AnyBody::Ellipsoid(_)) {
        fields.push(("shape", AttrValue::Text(body.shape_name().to_string())));
    }
    fields.extend(
        body.shape_parameters()
            .into_iter()
            .map(|(name, x)| (name, AttrValue::Number(x))),
    );
    if let AnyBody::Profile(b) = body {
        fields.push(("profile", AttrValue::Text(b.shape.profile.text())));
    }
    fields
}

/// [`body_fields`] as the start of a JSON object.
fn body_json(body: &AnyBody) -> serde_json::Map<String, serde_json::Value> {
    let mut value = serde_json::Map::new();
    if !matches!(body, AnyBody::Ellipsoid(_)) {
        value.insert("shape".into(), body.shape_name().into());
    }
    for (name, x) in body.shape_parameters() {
        value.insert(name.into(), x.into());
    }
    if let AnyBody::Profile(b) = body {
        value.insert(
            "profile".into(),
            serde_json::json!(b.shape.profile.points()),
        );
    }
    value
}

/// [`body_fields`] as text: `alpha=0.5 beta=3`, or `wheel alpha=0.1 cut=0.5`.
fn body_text(body: &AnyBody) -> String {
    let mut words = Vec::new();
    if !matches!(body, AnyBody::Ellipsoid(_)) {
        words.push(body.shape_name().to_string());
    }
    words.extend(
        body.shape_parameters()
            .into_iter()
            .map(|(name, x)| format!("{name}={}", show(x))),
    );
    words.join(" ")
}

/// Runs one parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    // The long commands stop at their next check on SIGINT, SIGTERM or SIGHUP, writing
    // nothing (`run` installs its own handlers, which keep its journal). (`merge` too: it
    // was killed by them, leaving its partial file and lock; adversary pass of 2026-11-28.)
    if matches!(
        cli.command,
        Command::Diagram(_)
            | Command::Trajectory(_)
            | Command::Resonance(_)
            | Command::Verdict(_)
            | Command::Merge(_)
    ) {
        crate::stop::install("nothing was written")
            .context("cannot install the SIGINT and SIGTERM handlers")?;
    }
    match cli.command {
        Command::Diagram(args) => diagram::diagram(args),
        Command::Trajectory(args) => trajectory::trajectory(args),
        Command::Cell(args) => cell::cell(args),
        Command::Run(args) => run::run_scene(args),
        Command::Merge(args) => merge::merge(args),
        Command::Resonance(args) => resonance::resonance(args),
        Command::Verdict(args) => verdict::verdict(args),
        Command::Completions { shell } => {
            // Into a buffer first: clap_complete panics when its writer fails (`> /dev/full`).
            let mut command = <Cli as clap::CommandFactory>::command();
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut command, "rubber-atlas", &mut script);
            use std::io::Write;
            let mut stdout = std::io::stdout().lock();
            stdout
                .write_all(&script)
                .and_then(|()| stdout.flush())
                .context(PRINTING_FAILED)
        }
        Command::Man {
            command,
            dir,
            force,
        } => man(command.as_deref(), dir.as_deref(), force),
    }
}

/// The manual pages: the program's (`rubber-atlas(1)`) and one per command
/// (`rubber-atlas-run(1)`, …, which the program's page lists), printed or written to `dir`.
fn man(name: Option<&str>, dir: Option<&std::path::Path>, force: bool) -> Result<()> {
    let mut program = <Cli as clap::CommandFactory>::command();
    program.build();
    // A command's page is named and titled as the program's page refers to it.
    // (clap names a command with a &'static str: the few page names are leaked, once.)
    let page_of = |c: &clap::Command| {
        let title: &'static str =
            Box::leak(format!("rubber-atlas-{}", c.get_name()).into_boxed_str());
        let usage = format!("rubber-atlas {}", c.get_name());
        clap_mangen::Man::new(c.clone().name(title).bin_name(usage)).title(title)
    };
    // (clap's `help` too: the program's page refers to rubber-atlas-help(1).)
    let commands: Vec<&clap::Command> = program.get_subcommands().collect();
    if let Some(dir) = dir {
        if !dir.is_dir() {
            return Err(rubber_atlas::AtlasError::Atlas {
                path: dir.display().to_string(),
                reason: "is not an existing folder".into(),
            }
            .into());
        }
        let mut pages = vec![(
            dir.join("rubber-atlas.1"),
            clap_mangen::Man::new(program.clone()),
        )];
        pages.extend(commands.iter().map(|c| {
            (
                dir.join(format!("rubber-atlas-{}.1", c.get_name())),
                page_of(c),
            )
        }));
        // Every page's path is checked before any is written, as any output is: a link, a
        // folder or a device is refused, and an existing page needs --force.
        for (path, _) in &pages {
            rubber_atlas::store::check_output(path, force, &[], &["1"])?;
        }
        for (path, page) in pages {
            let mut text = Vec::new();
            page.render(&mut text)
                .context("cannot render the manual page")?;
            rubber_atlas::store::write_bytes(&path, &text)?;
        }
        return Ok(());
    }
    let page = match name {
        None => clap_mangen::Man::new(program.clone()),
        Some(name) => {
            let c = commands
                .iter()
                .find(|c| c.get_name() == name)
                .ok_or_else(|| {
                    let names: Vec<&str> = commands.iter().map(|c| c.get_name()).collect();
                    anyhow::Error::new(rubber_atlas::AtlasError::Atlas {
                        path: format!("man {name}"),
                        reason: format!("no such command (commands: {})", names.join(", ")),
                    })
                })?;
            page_of(c)
        }
    };
    page.render(&mut std::io::stdout()).context(PRINTING_FAILED)
}

/// The attributes a command adds to the atlases it writes: its command line, the time, and
/// the CF `history`.
pub(crate) fn invocation_attributes() -> Vec<(String, AttrValue)> {
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

/// The root attributes of a table: the program and its commit, the command's invocation
/// ([`invocation_attributes`]) and `own`, the command's parameters (numbers as numbers).
pub(crate) fn table_attributes(own: &[(&str, AttrValue)]) -> Vec<(String, AttrValue)> {
    let mut attributes = rubber_atlas::store::program_attributes();
    attributes.extend(invocation_attributes());
    attributes.extend(own.iter().map(|(k, v)| (k.to_string(), v.clone())));
    attributes
}

/// Refuses options that the chosen start would silently ignore (clap's `requires` cannot see
/// this through the flattened start group).
/// A number on the command line, as Rust reads it, except that one whose digits are not all
/// zero must not read as 0 (`1e-400` underflows to 0.0: κ = 1e-400 would be the planar
/// κ = 0, η = 1e-400 "invalid eta = 0"). Subnormal values are kept: they are exact.
pub(crate) fn number(text: &str) -> std::result::Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("{text:?} is not a number"))?;
    let mantissa = text.trim().split(['e', 'E']).next().unwrap_or_default();
    let nonzero = mantissa.chars().any(|c| c.is_ascii_digit() && c != '0');
    if value == 0.0 && nonzero {
        return Err(format!(
            "{text} underflows: its size is below the smallest double (4.9e-324); give 0 or a number of larger size"
        ));
    }
    // (A typed inf is ±∞ and refused as such where it is; 1e309 was reported as "inf".)
    if value.is_infinite() && !mantissa.to_ascii_lowercase().contains("inf") {
        return Err(format!(
            "{text} overflows: its size is above the largest double (1.8e308)"
        ));
    }
    Ok(value)
}

pub(crate) fn check_start(start: &StartArgs, component: Option<usize>) -> Result<()> {
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

/// `text` as one word for a POSIX shell: as it is when it needs no quoting, else in single
/// quotes (a quote inside as '\'').
pub(crate) fn shell_quote(text: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_-./=:,+@%".contains(c);
    if !text.is_empty() && text.chars().all(plain) {
        text.to_string()
    } else {
        format!("'{}'", text.replace('\'', "'\\''"))
    }
}

/// The name a value has in the JSON output (`ok`, `libration`, `quadrature`), so that the
/// text output uses the same words.
pub(crate) fn json_name<T: serde::Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(name)) => name,
        Ok(other) => other.to_string(),
        Err(_) => String::from("?"),
    }
}

/// The command line as the files record it: its arguments as given, those that are not
/// UTF-8 (a file's name may be any bytes) with U+FFFD for each byte that is not.
/// (`std::env::args` panics on such an argument: every command that writes a file did,
/// after its work: adversary pass 42.)
pub(crate) fn command_line() -> String {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join(" ")
}

/// The context of an error writing a command's text to standard output (a full disk,
/// `> /dev/full`): `main` reports it as it reports a failed `println!`, in one line with the
/// program's name.
pub(crate) const PRINTING_FAILED: &str = "failed printing to stdout";

/// Tables (`diagram`, `trajectory`, `resonance`).
pub(crate) const TABLE_EXTENSIONS: [&str; 3] = ["csv", "h5", "hdf5"];
/// Atlases (`run`, `merge`).
pub(crate) const ATLAS_EXTENSIONS: [&str; 2] = ["h5", "hdf5"];
