//! `manylight`: render a scene to PNG, check a glTF file, benchmark pipelines, and measure
//! what accuracy and post stages cost, with tables, CSV and plots.
//!
//! `args` holds the command line; `commands` holds what each subcommand does with it; the
//! other modules measure, tabulate and plot.
#![warn(missing_docs)]

use args::{Cli, Command};
use clap::Parser;
use std::process::ExitCode;

mod args;
mod bench;
mod camera_spec;
mod codec_accuracy;
mod commands;
mod culling_tests;
mod depth_precision;
mod direct;
mod environment_accuracy;
mod large_floor;
mod plot;
mod post;
mod progress;
mod ray_cost;
mod report;
mod shadow_error;
mod soak;
mod views;

/// Parses the command line and runs its subcommand; exits 1 with the error when it fails.
fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| "warn,manylight=info".into()),
        )
        .with_writer(std::io::stderr)
        .init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => commands::render::run(args),
        Command::Check { path } => commands::check::run(path),
        Command::Bench(args) => commands::bench::run(args),
        Command::Report(args) => commands::report::run(args),
        Command::RangelessLights(args) => commands::report::rangeless_lights(args),
        Command::Post(args) => commands::post::run(args),
        Command::Views(args) => commands::views::run(args),
        Command::EnvironmentAccuracy(args) => commands::environment_accuracy::run(args),
        Command::ShadowRays(args) => commands::shadow_rays::run(args),
        Command::Plot { csv, out } => commands::plot::run(csv, out),
        Command::Compare { reference, test, error_map } => {
            commands::compare::run(&reference, &test, error_map.as_deref())
        }
        Command::Soak(args) => soak::run(args),
        Command::DepthPrecision { samples } => commands::cpu_tables::depth_precision(samples),
        Command::CodecAccuracy { samples } => commands::cpu_tables::codec_accuracy(samples),
        Command::CullingTests { lights, seed } => commands::cpu_tables::culling_tests(lights, seed),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
