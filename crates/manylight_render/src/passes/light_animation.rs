//! The light animation pass: the frame's one dispatch of `shaders/light_animation.wgsl`, which
//! writes every GPU-animated light's position and colour into the light buffer
//! ([`crate::animation`]). Not a pass of a view's graph: the renderer records it first in the
//! frame's first command encoder, whatever the views, when the frame readied it.

use super::common::{compute_pipeline, dispatch_size};
use crate::animation::WORKGROUP_SIZE;
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName};
use crate::pipelines::PipelineKey;

/// The pipeline key of [`LightAnimationPass`] (one pipeline).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LightAnimationKey;

impl PipelineKey for LightAnimationKey {
    type Pipeline = wgpu::ComputePipeline;
}

/// Records the frame's light animation dispatch ([`crate::animation::LightMotions::dispatch`]).
pub struct LightAnimationPass;

impl NamedPass for LightAnimationPass {
    const NAME: &'static str = "light_animation";
}

impl Pass for LightAnimationPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn reads(&self) -> Vec<ResourceName> {
        Vec::new()
    }

    fn writes(&self) -> Vec<ResourceName> {
        Vec::new()
    }

    fn is_compute(&self) -> bool {
        true
    }

    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let Some((layout, group)) = ctx.scene.lights.motions.dispatch() else {
            return Ok(());
        };
        let device = &ctx.gpu.device;
        let pipeline = ctx.pipelines.get_or_create(LightAnimationKey, |_| {
            let constants = [("WORKGROUP_SIZE", f64::from(WORKGROUP_SIZE))];
            compute_pipeline(device, Self::NAME, "light_animation.wgsl", &[layout], "main", &constants)
        })?;
        let max_groups = ctx.gpu.device.limits().max_compute_workgroups_per_dimension;
        let [x, y] = dispatch_size(ctx.scene.lights.count, WORKGROUP_SIZE, max_groups)?;
        let timestamps = ctx.compute_timestamps(true, true);
        let mut pass = ctx.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(Self::NAME),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(crate::layouts::LIGHT_ANIMATION_GROUP.index, group, &[]);
        pass.dispatch_workgroups(x, y, 1);
        Ok(())
    }
}
