//! What `views` does: loads the scene, checks its lights, and prints what 1, 2 and 4 cameras
//! over the same pixels cost (the `views` module).

use super::shared::{check_lights, measure_base, scene_name};
use crate::args::ViewsArgs;
use crate::views;
use anyhow::Result;

/// `views`: the table of what 1, 2 and 4 views of the same pixels cost.
pub(crate) fn run(args: ViewsArgs) -> Result<()> {
    let scene = args.clusters.load(&args.scene)?;
    check_lights(scene.lights.len().saturating_add(args.lights), "--lights")?;
    let base = measure_base(&args.clusters, &args.scene);
    let name = scene_name(&args.scene);
    print!("{}", views::run(&scene, &name, args.lights, args.size, args.frames.max(1), base)?);
    Ok(())
}
