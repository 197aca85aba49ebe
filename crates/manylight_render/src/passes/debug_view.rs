//! Debug view: replaces tone mapping with the per-pixel light count of the pixel's cluster (a
//! heatmap with a legend bar) or the cluster x / y / z index.

use super::common::{draw_fullscreen, fullscreen_pipeline, storage_entry, texture_entry, uniform_entry};
use super::{CLUSTERS, DEPTH};
use crate::context::RenderError;
use crate::graph::{OUTPUT, Pass, PassContext, ResourceName};
use crate::pipelines::format_key;
use crate::snapshot::DebugView;
use wgpu::util::DeviceExt;

/// The pipeline of [`DebugViewPass`] for one output format.
pub struct DebugViewPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl DebugViewPipeline {
    fn new(device: &wgpu::Device, output: wgpu::TextureFormat) -> Result<Self, RenderError> {
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("debug_view"),
            entries: &[
                uniform_entry(0, fragment),
                texture_entry(1, wgpu::TextureSampleType::Depth),
                uniform_entry(2, fragment),
                storage_entry(3, fragment, true),
                uniform_entry(4, fragment),
            ],
        });
        let pipeline =
            fullscreen_pipeline(device, "debug_view", "debug_view.wgsl", &[&layout], "fs_main", output)?;
        Ok(DebugViewPipeline { pipeline, layout })
    }
}

/// Writes a debug visualisation to [`OUTPUT`].
pub struct DebugViewPass {
    /// What to show (not `DebugView::None`).
    pub view: DebugView,
    /// Light count drawn as the hottest colour of the heatmap.
    pub heatmap_max: u32,
}

impl Pass for DebugViewPass {
    fn name(&self) -> &'static str {
        "debug_view"
    }
    fn reads(&self) -> Vec<ResourceName> {
        vec![DEPTH, CLUSTERS]
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![OUTPUT]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters =
            ctx.clusters.ok_or_else(|| RenderError::Graph("debug_view needs cluster resources".into()))?;
        let format = ctx.output_format;
        let device = &ctx.gpu.device;
        let pipeline =
            ctx.pipelines.get_or_create(format_key(format), || DebugViewPipeline::new(device, format))?;
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("debug_view_params"),
            contents: bytemuck::cast_slice(&[self.view.gpu_id(), self.heatmap_max.max(1), 0, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("debug_view"),
            layout: &pipeline.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: ctx.scene.view_buffer.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(ctx.texture(DEPTH)?),
                },
                wgpu::BindGroupEntry { binding: 2, resource: clusters.params_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: clusters.ranges.buffer().as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: params.as_entire_binding() },
            ],
        });
        let output = ctx.texture(OUTPUT)?;
        let timestamps = ctx.render_timestamps(true, true);
        draw_fullscreen(ctx.encoder, "debug_view", output, timestamps, &pipeline.pipeline, &[&bind_group]);
        Ok(())
    }
}
