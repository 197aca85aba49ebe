//! What `post` does: loads the scene, checks its lights, measures the frame with and without
//! bloom and motion blur (the `post` module), prints the table and, with `--plot`, writes its
//! CSV and figures.

use super::shared::{check_lights, measure_base, scene_name, write_plots};
use crate::args::ReportArgs;
use crate::post;
use anyhow::Result;

/// `post`: the post-stage cost table, and its CSV and figures with `--plot`.
pub(crate) fn run(args: ReportArgs) -> Result<()> {
    let scene = args.clusters.load(&args.scene)?;
    check_lights(scene.lights.len().saturating_add(args.lights), "--lights")?;
    let base = measure_base(&args.clusters, &args.scene);
    let name = scene_name(&args.scene);
    let report = post::run(&scene, &name, args.lights, args.size, args.frames.max(1), base)?;
    print!("{}", report.markdown);
    if let Some(dir) = &args.plot {
        write_plots(dir, "post", &report.csv)?;
    }
    Ok(())
}
