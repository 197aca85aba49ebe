//! What `shadow-rays` does: measures the shadow-ray BVH (the `ray_cost` module) and prints its
//! tables.

use crate::args::ShadowRaysArgs;
use crate::ray_cost::{Options, markdown, measure};
use anyhow::Result;

/// `shadow-rays`: the cost of building the scene's two-level BVH and of tracing shadow rays
/// through it.
pub(crate) fn run(args: ShadowRaysArgs) -> Result<()> {
    super::shared::check_lights(args.lights, "--lights")?;
    let options = Options {
        scene: args.scene,
        lights: args.lights,
        size: args.size,
        rays_per_pixel: args.rays_per_pixel,
        seed: args.seed,
        repeats: args.repeats,
    };
    print!("{}", markdown(&measure(&options)?));
    Ok(())
}
