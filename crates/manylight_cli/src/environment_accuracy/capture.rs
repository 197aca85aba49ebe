//! The frame's HDR image before tone mapping, read back: a compute pass added before the tone
//! map (an app stage, [`FramePlanner::insert_before`]) copies the HDR target into a storage
//! buffer, which [`read`] brings to the CPU after the frame. The shading passes create the HDR
//! target without `COPY_SRC`, so a texture copy cannot do it.

use anyhow::{Context, Result};
use glam::Vec3;
use manylight_render::graph::{Pass, PassContext, ResourceName};
use manylight_render::passes::{HDR, TonemapPass};
use manylight_render::pipelines::PipelineKey;
use manylight_render::{FramePlanner, GpuContext, PlanInputs, RenderError, Stage, wgpu};
use std::sync::{Arc, Mutex};

/// The pass's WGSL: one thread per pixel, `texels[y * width + x] = hdr[x, y]`.
const WGSL: &str = "
    @group(0) @binding(0) var hdr: texture_2d<f32>;
    @group(0) @binding(1) var<storage, read_write> texels: array<vec4<f32>>;

    @compute @workgroup_size(8, 8, 1)
    fn cs_capture(@builtin(global_invocation_id) id: vec3<u32>) {
        let size = textureDimensions(hdr);
        if id.x >= size.x || id.y >= size.y {
            return;
        }
        texels[id.y * size.x + id.x] = textureLoad(hdr, vec2<i32>(id.xy), 0);
    }
";

/// The buffer the last captured frame was written into, with its width and height. A stage is
/// planned by a plain function, so the pass finds its buffer here.
static CAPTURED: Mutex<Option<(wgpu::Buffer, u32, u32)>> = Mutex::new(None);

/// The stages of a frame whose HDR image is captured: the built-in ones, the capture right
/// before the tone map.
pub fn capturing_stages() -> Result<Arc<FramePlanner>> {
    let mut stages = FramePlanner::default();
    stages.insert_before::<TonemapPass>(Stage::new::<HdrCapture>(plan))?;
    Ok(Arc::new(stages))
}

/// The last captured frame's HDR image, linear RGB per pixel, row-major (waits for the GPU).
pub fn read(gpu: &GpuContext) -> Result<Vec<Vec3>> {
    let (buffer, width, height) = CAPTURED
        .lock()
        .map_err(|_| anyhow::anyhow!("capture lock poisoned"))?
        .clone()
        .context("no frame was captured")?;
    let bytes = manylight_render::readback::read_buffer(gpu, &buffer, 0, buffer.size())?;
    // Each texel is four little-endian f32: red, green, blue, alpha.
    let texels = bytes.chunks_exact(16).take(width as usize * height as usize).map(|c| {
        let f = |i: usize| f32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
        Vec3::new(f(0), f(4), f(8))
    });
    Ok(texels.collect())
}

/// Copies the HDR image into the capture buffer.
struct HdrCapture;

/// Its pipeline has one variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct HdrCaptureKey;

impl PipelineKey for HdrCaptureKey {
    type Pipeline = wgpu::ComputePipeline;
}

/// Whenever the image is shown (no debug view replaces it).
fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn Pass>>) {
    if p.shows_image() {
        out.push(Box::new(HdrCapture));
    }
}

impl Pass for HdrCapture {
    fn name(&self) -> &'static str {
        "hdr_capture"
    }
    fn reads(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    // Listed as written so that the tone map depends on it and the graph keeps it.
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn is_compute(&self) -> bool {
        true
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let device = &ctx.gpu.device;
        let pipeline = ctx.pipelines.get_or_create(HdrCaptureKey, |_| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("hdr_capture"),
                source: wgpu::ShaderSource::Wgsl(WGSL.into()),
            });
            Ok::<_, RenderError>(device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("hdr_capture"),
                layout: None,
                module: &module,
                entry_point: Some("cs_capture"),
                compilation_options: Default::default(),
                cache: None,
            }))
        })?;
        let hdr = ctx.texture(HDR)?;
        let (width, height) = (hdr.texture().width(), hdr.texture().height());
        let mut captured = CAPTURED.lock().map_err(|_| RenderError::Graph("capture lock poisoned".into()))?;
        if captured.as_ref().is_some_and(|(_, w, h)| (*w, *h) != (width, height)) {
            *captured = None;
        }
        let (buffer, _, _) = captured.get_or_insert_with(|| {
            let buffer = ctx.gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("hdr_capture"),
                size: u64::from(width) * u64::from(height) * 16,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            (buffer, width, height)
        });
        let group = ctx.gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("hdr_capture"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(hdr) },
                wgpu::BindGroupEntry { binding: 1, resource: buffer.as_entire_binding() },
            ],
        });
        let timestamps = ctx.compute_timestamps(true, true);
        let mut pass = ctx.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("hdr_capture"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(width.div_ceil(8), height.div_ceil(8), 1);
        Ok(())
    }
}
