//! The `light_refine` pass: refined light lists (`shaders/light_refine.wgsl`). One compute
//! pass after the cluster build keeps, for every block of `REFINE_EDGE` × `REFINE_EDGE`
//! pixels, the lights of its pixels' cluster lists that reach the box around their surface
//! positions; the shading passes read a block's list instead of its pixels' cluster lists
//! ([`crate::snapshot::ClusterSettings::refined_lists`]).

use super::cluster_depth::DistanceSource;
use super::common::texture_entry;
use super::gbuffer_layout::{codec_constants, gbuffer_read_bind_group, gbuffer_read_layout, gbuffer_reads};
use super::{CLUSTERS, DEPTH, SHADING_DISTANCE};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::gpu_types::REFINE_EDGE;
use crate::graph::{Pass, PassContext, ResourceName};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::snapshot::GBufferLayout;
use manylight_core::codec::NormalCodec;

/// The pipeline key of [`LightRefinePass`]: where it reads the shading distances.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RefineKey(pub DistanceSource);

impl PipelineKey for RefineKey {
    type Pipeline = LightRefinePipeline;
}

/// The pipeline of [`LightRefinePass`] for one source, and the layout of its group 1.
pub struct LightRefinePipeline {
    pipeline: wgpu::ComputePipeline,
    source_layout: wgpu::BindGroupLayout,
}

impl LightRefinePipeline {
    fn new(
        device: &wgpu::Device,
        view_layout: &wgpu::BindGroupLayout,
        refine_layout: &wgpu::BindGroupLayout,
        source: DistanceSource,
    ) -> Result<Self, RenderError> {
        let (source_layout, entry, constants) = match source {
            DistanceSource::Prepass => {
                let unfilterable = wgpu::TextureSampleType::Float { filterable: false };
                let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("shading_distance"),
                    entries: &[texture_entry(9, unfilterable)],
                });
                (layout, "cs_forward", codec_constants(NormalCodec::Octa16))
            }
            DistanceSource::GBuffer(layout, codec) => {
                let entry = match layout {
                    GBufferLayout::Full => "cs_full",
                    GBufferLayout::Packed => "cs_packed",
                    GBufferLayout::Compact => "cs_compact",
                };
                (gbuffer_read_layout(device, layout), entry, codec_constants(codec))
            }
        };
        let module = crate::shaders::create_module(device, "light_refine.wgsl")?;
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("light_refine"),
            bind_group_layouts: &[Some(view_layout), Some(&source_layout), Some(refine_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("light_refine"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            },
            cache: None,
        });
        Ok(LightRefinePipeline { pipeline, source_layout })
    }
}

/// Writes every pixel block's refined list and range after the cluster lists and ranges.
pub struct LightRefinePass {
    /// Where the shading distances come from.
    pub source: DistanceSource,
    /// The view's clear colour (the G-buffer read group holds it).
    pub clear_color: [f32; 3],
}

impl Pass for LightRefinePass {
    fn name(&self) -> &'static str {
        "light_refine"
    }
    fn reads(&self) -> Vec<ResourceName> {
        let mut reads: Vec<ResourceName> = match self.source {
            DistanceSource::Prepass => vec![SHADING_DISTANCE, DEPTH],
            DistanceSource::GBuffer(layout, _) => gbuffer_reads(layout).collect(),
        };
        reads.push(CLUSTERS);
        reads
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![CLUSTERS]
    }
    fn is_compute(&self) -> bool {
        true
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters =
            ctx.clusters.ok_or_else(|| RenderError::Graph("light_refine needs cluster resources".into()))?;
        let scene = ctx.scene;
        let device = &ctx.gpu.device;
        let pipeline = ctx.pipelines.get_or_create(RefineKey(self.source), |&RefineKey(source)| {
            LightRefinePipeline::new(device, &scene.view_layout, &clusters.refine_layout, source)
        })?;
        let source = match self.source {
            DistanceSource::Prepass => ctx.bind_group_numbered(
                "shading_distance",
                &pipeline.source_layout,
                &[(9, Binding::Texture(ctx.texture(SHADING_DISTANCE)?))],
            ),
            DistanceSource::GBuffer(layout, _) => {
                gbuffer_read_bind_group(ctx, &pipeline.source_layout, layout, self.clear_color)?
            }
        };
        let lists = ctx.bind_group(
            "light_refine",
            &clusters.refine_layout,
            &[
                Binding::Buffer(&clusters.params_buffer),
                Binding::Buffer(clusters.spheres.buffer()),
                Binding::Buffer(clusters.ranges.buffer()),
                Binding::Buffer(clusters.indices.buffer()),
            ],
        );
        let p = &clusters.params;
        let groups = [p.refine_blocks_x.div_ceil(8), p.refine_blocks_y.div_ceil(8)];
        let timestamps = ctx.compute_timestamps(true, true);
        let mut pass = ctx.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("light_refine"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&pipeline.pipeline);
        pass.set_bind_group(0, &scene.view_bind_group, &[]);
        pass.set_bind_group(1, &source, &[]);
        pass.set_bind_group(2, &lists, &[]);
        pass.dispatch_workgroups(groups[0], groups[1], 1);
        Ok(())
    }
}

/// Needed when the view refines its lists (`PlanInputs::refines_lists`): from the G-buffer when
/// it is shaded deferred, else from the depth pre-pass. `REFINE_EDGE` pixels a block edge.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    const _: () = assert!(REFINE_EDGE > 0);
    if p.refines_lists() {
        let s = p.settings();
        let source = if p.shades_deferred() {
            DistanceSource::GBuffer(s.gbuffer, s.normal_codec)
        } else {
            DistanceSource::Prepass
        };
        out.push(Box::new(LightRefinePass { source, clear_color: s.clear_color }));
    }
}
