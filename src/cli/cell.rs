//! `rubber-atlas cell`: one cell (κ, ε) or the component of one start, as text or JSON.

use super::*;
use anyhow::Result;
use clap::Args;
use rubber_atlas::cell::{solve_cell, solve_start, CellOptions, CellResult, Method, Status};
use rubber_atlas::torus::EffectivePotential;
use rubber_atlas::{Body, Shape};

#[derive(Debug, Args)]
pub struct CellArgs {
    #[command(flatten)]
    pub level: LevelArgs,
    #[command(flatten)]
    pub start: StartArgs,
    /// Accuracy: relative for T, ω, drift; absolute for N. 1e-15 <= TOL <= 0.1.
    #[arg(value_parser = number, long, default_value_t = 1e-10, allow_hyphen_values = true)]
    pub tol: f64,
    /// How to compute the period integrals.
    #[arg(long, value_enum, default_value_t = MethodArg::Quadrature)]
    pub method: MethodArg,
    /// |N − round(N)| at or below this (or N's error estimate) counts as a resonance.
    #[arg(value_parser = number, long, default_value_t = 1e-9, allow_hyphen_values = true)]
    pub resonance_tol: f64,
    /// Print one JSON object (keys of docs/files.md).
    #[arg(long)]
    pub json: bool,
}

/// The cell (or the component of the start) of `body`.
fn solve<S: Shape>(body: &Body<S>, args: &CellArgs, options: &CellOptions) -> Result<CellResult> {
    Ok(match (args.start.energy, args.start.theta0) {
        (Some(e), _) => solve_cell(body, args.level.kappa, e, options)?,
        (None, Some(t)) => {
            // Only the component that holds θ(0).
            let start = args.start.at_theta0(args.level.kappa, t)?;
            options.validate()?;
            options.check_for(body)?;
            let potential = EffectivePotential::new(body, start.kappa);
            start.checked_energy(body)?;
            let energy = start.level(&potential);
            let component = start.component_in(&potential)?;
            CellResult {
                kappa: start.kappa,
                energy,
                status: Status::Ok,
                components: vec![solve_start(
                    &potential, &start, energy, &component, options,
                )?],
            }
        }
        (None, None) => unreachable!("clap requires --energy or --theta0"),
    })
}

pub(super) fn cell(args: CellArgs) -> Result<()> {
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
    let result = rubber_atlas::with_body!(&body, b => solve(b, &args, &options))?;
    let energy = result.energy;
    if args.json {
        // The ellipsoid's object as it always was; another shape adds its name.
        let mut value = body_json(&body);
        let rest = serde_json::json!({
            "nu": args.level.nu,
            "eta": args.level.eta,
            "kappa": args.level.kappa,
            "energy": energy,
            "tolerance": args.tol,
            "method": options.method,
            "status": result.status,
            "components": result.components,
        });
        if let serde_json::Value::Object(rest) = rest {
            value.extend(rest);
        }
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    println!(
        "cell {} nu={} eta={} kappa={} energy={} ({}, tol {:e}): {}",
        body_text(&body),
        show(args.level.nu),
        show(args.level.eta),
        show(args.level.kappa),
        show(energy),
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
