//! What `report` and `rangeless-lights` do: load the scene, check its lights, run the tables of
//! the `report` module, print them as markdown and, with `--plot`, write their CSV and figures.

use super::shared::{check_lights, measure_base, scene_name, write_plots};
use crate::args::ReportArgs;
use crate::large_floor;
use crate::report::{self, Report};
use anyhow::Result;

/// `report`: the accuracy-against-time tables, or with `--shadows` or `--large-floor` that
/// section instead.
pub(crate) fn run(args: ReportArgs) -> Result<()> {
    if args.large_floor {
        let base = measure_base(&args.clusters, "default").render;
        print!("{}", large_floor::run(&args.floor_extents, args.floor_far, args.size, base)?);
        return Ok(());
    }
    let scene = args.clusters.load(&args.scene)?;
    check_lights(scene.lights.len().saturating_add(args.lights), "--lights")?;
    let base = measure_base(&args.clusters, &args.scene);
    let name = scene_name(&args.scene);
    let (frames, size) = (args.frames.max(1), args.size);
    let (report, csv_name) = if args.shadows {
        let shadows = report::shadows(&scene, &name, args.lights, size, frames, base)?;
        (Report { markdown: format!("## Shadows\n\n{}", shadows.markdown), ..shadows }, "report_shadows")
    } else {
        (report::run(&scene, &name, args.lights, size, frames, base)?, "report")
    };
    print!("{}", report.markdown);
    if let Some(dir) = &args.plot {
        write_plots(dir, csv_name, &report.csv)?;
    }
    Ok(())
}

/// `rangeless-lights`: only the last table of `report`.
pub(crate) fn rangeless_lights(args: ReportArgs) -> Result<()> {
    let scene = args.clusters.load(&args.scene)?;
    check_lights(scene.lights.len().saturating_add(args.lights), "--lights")?;
    let mut renderer = manylight_app::render_world::HeadlessRenderer::new()?;
    let (lights, size, frames) = (args.lights, args.size, args.frames.max(1));
    print!(
        "{}",
        report::rangeless_lights(
            &mut renderer,
            &scene,
            lights,
            size,
            frames,
            measure_base(&args.clusters, &args.scene)
        )?
    );
    Ok(())
}
