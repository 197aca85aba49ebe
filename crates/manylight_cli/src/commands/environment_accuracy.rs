//! What `environment-accuracy` does: measures split-sum image-based lighting against the
//! Monte-Carlo reference (the `environment_accuracy` module), prints the tables, and writes
//! the CSV and the figure when asked.

use crate::args::EnvironmentAccuracyArgs;
use crate::environment_accuracy::{self, Options, figure, table};
use anyhow::{Context, Result};

/// `environment-accuracy`: the tables of split-sum's error and prefilter cost per setting.
pub(crate) fn run(args: EnvironmentAccuracyArgs) -> Result<()> {
    let start = std::time::Instant::now();
    let options = Options {
        environment: args.environment,
        size: args.size,
        reference_samples: args.reference_samples,
        frames: args.frames,
    };
    let measurement = environment_accuracy::measure(&options)?;
    print!("{}", table::markdown(&measurement));
    if let Some(path) = &args.csv {
        std::fs::write(path, table::csv(&measurement)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.figure {
        figure::draw(path, &measurement)?;
        eprintln!("wrote {}", path.display());
    }
    let [reference, core, split_sum, gpu] = measurement.seconds;
    eprintln!(
        "took {:.0} s: references {reference:.0} s, core's reference {core:.0} s, CPU split-sums {split_sum:.0} s, GPU settings {gpu:.0} s",
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
