//! Reads back the shadow test the shading passes make, at chosen light–point pairs: the
//! measurement side of shadows (`manylight render --shadow-oracle` compares it with the exact
//! visibility of `manylight_core::shadow_oracle`). It runs `shaders/shadow_probe.wgsl`, which
//! calls the very `shadow_visibility` of the shading passes against the last frame's atlas and
//! light table, so what is measured is what was shaded. Not part of a frame.

use crate::bindings::Binding;
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::{GpuPointLight, GpuShadowProbe};
use crate::layouts::{SHADOW_PROBE_GROUP, SHADOW_PROBE_SHADOWS_GROUP, check_pipeline, pipeline_layout};
use crate::readback::{dispatch_and_read, readback_output};
use crate::shaders::ShaderDefs;
use crate::shadows::ShadowResources;
use glam::Vec3;

/// Probes evaluated per dispatch (32 MiB of probes): a frame's millions of pairs go in parts.
pub const PROBES_PER_DISPATCH: usize = 1 << 20;

/// Workgroup size of `shadow_probe.wgsl`.
const WORKGROUP: u32 = 64;

/// One light–point pair to probe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowProbe {
    /// The surface point, in world space.
    pub position: Vec3,
    /// The surface's normal (any length).
    pub normal: Vec3,
    /// The light's index in the frame's light buffer (its valid lights, in order).
    pub light: u32,
}

impl From<&ShadowProbe> for GpuShadowProbe {
    fn from(p: &ShadowProbe) -> GpuShadowProbe {
        GpuShadowProbe {
            position: p.position.to_array(),
            light: p.light,
            normal: p.normal.to_array(),
            pad: 0.0,
        }
    }
}

/// The shadow test of `shadows`' last frame for each probe, in [0, 1] (1: fully lit). Every
/// probe is 1 when that frame drew no shadow map; a probe of a light the buffer lacks is 1.
/// `lights` is the frame's light buffer (`SceneLights::buffer`), holding `light_count`
/// lights. Waits for the GPU.
pub fn probe_shadows(
    gpu: &GpuContext,
    shadows: &ShadowResources,
    lights: &wgpu::Buffer,
    light_count: u32,
    probes: &[ShadowProbe],
) -> Result<Vec<f32>, RenderError> {
    let Some(bindings) = shadows.bindings() else {
        return Ok(vec![1.0; probes.len()]);
    };
    if probes.is_empty() || light_count == 0 {
        return Ok(vec![1.0; probes.len()]);
    }
    let module = crate::shaders::create_module(&gpu.device, "shadow_probe.wgsl")
        .map_err(|e| RenderError::Graph(format!("shadow_probe.wgsl: {e}")))?;
    let defs = ShaderDefs::default();
    let shadow_layout = SHADOW_PROBE_SHADOWS_GROUP.create_layout(&gpu.device, defs);
    let probe_layout = SHADOW_PROBE_GROUP.create_layout(&gpu.device, defs);
    check_pipeline("shadow_probe.wgsl", &["main"], &[&shadow_layout, &probe_layout])?;
    let pipeline_layout = pipeline_layout(&gpu.device, "shadow_probe", &[&shadow_layout, &probe_layout]);
    let pipeline = gpu.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("shadow_probe"),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let shadow_group = shadow_layout.create_bind_group(
        gpu,
        &[
            Binding::Texture(bindings.atlas),
            Binding::Sampler(bindings.sampler),
            Binding::Buffer(bindings.lights),
            Binding::Buffer(bindings.directional),
        ],
    );
    let light_bytes = u64::from(light_count) * std::mem::size_of::<GpuPointLight>() as u64;
    let Some(light_bytes) = wgpu::BufferSize::new(light_bytes) else {
        return Ok(vec![1.0; probes.len()]);
    };
    let mut out = Vec::with_capacity(probes.len());
    for part in probes.chunks(PROBES_PER_DISPATCH) {
        let gpu_probes: Vec<GpuShadowProbe> = part.iter().map(GpuShadowProbe::from).collect();
        let input = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow_probes"),
            contents: bytemuck::cast_slice(&gpu_probes),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let result_bytes = (part.len() * 4) as u64;
        let output = readback_output(gpu, "shadow_probed", result_bytes);
        let group = probe_layout.create_bind_group(
            gpu,
            &[Binding::BufferPrefix(lights, light_bytes), Binding::Buffer(&input), Binding::Buffer(&output)],
        );
        // Groups in index order: SHADOW_PROBE_SHADOWS_GROUP (0), SHADOW_PROBE_GROUP (1).
        let groups = [&shadow_group, &group];
        let size = (part.len() as u32, WORKGROUP);
        let bytes = dispatch_and_read(gpu, "shadow_probe", &pipeline, &groups, size, &output, result_bytes)?;
        out.extend_from_slice(&bytemuck::pod_collect_to_vec::<u8, f32>(&bytes)[..part.len()]);
    }
    Ok(out)
}
