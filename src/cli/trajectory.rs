//! `rubber-atlas trajectory`: a time history of the reduced or the full model, as a table
//! file.

use super::*;
use anyhow::Result;
use clap::{ArgGroup, Args};
use rubber_atlas::cf::AttrValue;
use rubber_atlas::error::AtlasError;
use rubber_atlas::store::{check_output, write_table_until};
use rubber_atlas::trajectory::{self, Duration, Model, StartAt};
use std::path::PathBuf;

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("length").required(true).args(["periods", "t_end"])))]
pub struct TrajectoryArgs {
    #[command(flatten)]
    pub level: LevelArgs,
    #[command(flatten)]
    pub start: StartArgs,
    /// Which component of the level set (κ, ε) to start on, counted from the smallest θ
    /// (with --energy) [default: 0].
    #[arg(long, requires = "energy", allow_hyphen_values = true)]
    pub component: Option<usize>,
    /// Length in θ-periods of the starting component.
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub periods: Option<f64>,
    /// Length in time units √(b3/g).
    #[arg(value_parser = number, long, allow_hyphen_values = true)]
    pub t_end: Option<f64>,
    /// Number of output intervals (the file has SAMPLES + 1 rows).
    #[arg(long, default_value_t = 2000, allow_hyphen_values = true)]
    pub samples: usize,
    #[command(flatten)]
    pub limits: Limits,
    /// Relative and absolute tolerance of the DOP853 integrator, 1e-15 ... 0.1.
    #[arg(value_parser = number, long, default_value_t = 1e-12, allow_hyphen_values = true)]
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

pub(super) fn trajectory(args: TrajectoryArgs) -> Result<()> {
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
    // A CSV row of 10 columns is under 250 bytes.
    let rows = args.samples as f64 + 1.0;
    let memory = rubber_atlas::trajectory::MEMORY_PER_SAMPLE * rows;
    args.limits
        .check(memory, Some(250.0 * rows), Some(&args.out), &|| {
            "use fewer --samples".into()
        })?;
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
        step_budget: (!args.limits.allow_large).then_some(trajectory::STEP_BUDGET),
    };
    let (start, traj, energy) = rubber_atlas::with_body!(&body, b => request
        .run_until(b, &crate::stop::requested)
        .map(|(start, traj)| (start, traj, start.energy(b))))?;
    let (tol, t_end) = (args.tol, traj.t.last().copied().unwrap_or(0.0));
    let mut table = rubber_atlas::table::trajectory(&traj);
    // The ellipsoid's attributes as they always were; another shape adds its name.
    let mut attributes: Vec<(&str, AttrValue)> =
        vec![("model", AttrValue::Text(json_name(&model)))];
    attributes.extend(body_fields(&body));
    attributes.extend([
        ("nu", AttrValue::Number(args.level.nu)),
        ("eta", AttrValue::Number(args.level.eta)),
        ("kappa", AttrValue::Number(start.kappa)),
        ("energy", AttrValue::Number(energy)),
        ("theta0", AttrValue::Number(start.theta0)),
        ("theta_dot0", AttrValue::Number(start.theta_dot0)),
        ("tolerance", AttrValue::Number(tol)),
        ("energy_drift", AttrValue::Number(traj.energy_drift)),
    ]);
    table.attributes.extend(table_attributes(&attributes));
    write_table_until(&args.out, &table, &crate::stop::requested)?;
    say!(
        "wrote {} samples over t in [0, {}] ({} model, energy kept to {:.1e}) to {}",
        traj.t.len(),
        show(t_end),
        json_name(&model),
        traj.energy_drift,
        args.out.display()
    );
    Ok(())
}
