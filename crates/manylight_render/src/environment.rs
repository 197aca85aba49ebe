//! Environment maps on the GPU: each panorama a view names is prefiltered once, in compute
//! (`shaders/environment_prefilter.wgsl`), into a specular cube (one GGX roughness per mip)
//! and an irradiance cube, beside one split-sum lookup table; group 0 binds them for the
//! views that name the panorama. A frame whose views name none creates, dispatches and binds
//! nothing.

use crate::bindings::Binding;
use crate::context::{GpuContext, RenderError};
use crate::layouts::{ENV_FILTER_GROUP, ENV_FROM_EQUIRECT_GROUP, ENV_LUT_GROUP, GroupLayout};
use crate::settings::{EnvironmentFilter, EnvironmentHandle};
use crate::snapshot::FrameSnapshot;
use bytemuck::{Pod, Zeroable};
use manylight_core::environment::EquirectImage;
use web_time::Instant;

/// Frames a prefiltered environment stays on the GPU after the last view that named it.
pub const ENVIRONMENT_KEEP_FRAMES: u64 = 60;

/// Format of every cube and of the lookup table: f16 holds HDR radiance (clamped to its
/// largest value) and is filterable and writable from compute everywhere.
pub const ENVIRONMENT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// GGX samples per texel of the split-sum lookup table.
pub const LUT_SAMPLES: u32 = 512;

/// The parameters of one prefilter dispatch (`GpuEnvironmentFilter` in
/// `shaders/environment_prefilter.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuEnvironmentFilter {
    /// Face (or table) size of what the dispatch writes.
    pub size: u32,
    /// Samples per texel, or reads per axis for `cs_from_equirect`.
    pub samples: u32,
    /// GGX perceptual roughness of the specular mip written
    /// ([`EnvironmentFilter::specular_mip_roughness`]).
    pub roughness: f32,
    /// The source cube's mip-0 face size.
    pub source_size: f32,
    /// The source cube's largest mip level.
    pub source_max_lod: f32,
    /// The panorama's width.
    pub equirect_width: u32,
    /// The panorama's height.
    pub equirect_height: u32,
    /// Padding to 16 bytes.
    pub _pad: u32,
}

/// One panorama, prefiltered.
struct Prefiltered {
    handle: EnvironmentHandle,
    filter: EnvironmentFilter,
    specular: wgpu::TextureView,
    irradiance: wgpu::TextureView,
    last_used: u64,
    generation: u64,
}

/// What group 0 binds for a view's environment.
pub struct EnvironmentBindings<'a> {
    /// The specular cube (all mips).
    pub specular: &'a wgpu::TextureView,
    /// The irradiance cube.
    pub irradiance: &'a wgpu::TextureView,
    /// The split-sum lookup table.
    pub lut: &'a wgpu::TextureView,
    /// Their sampler (trilinear, clamped).
    pub sampler: &'a wgpu::Sampler,
    /// Changes whenever one of them is re-created.
    pub generation: u64,
}

struct FilterPipelines {
    from_equirect: wgpu::ComputePipeline,
    downsample: wgpu::ComputePipeline,
    specular: wgpu::ComputePipeline,
    irradiance: wgpu::ComputePipeline,
    lut: wgpu::ComputePipeline,
    from_equirect_layout: GroupLayout,
    filter_layout: GroupLayout,
    lut_layout: GroupLayout,
}

/// What the frame's environments took.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct EnvironmentReport {
    /// Panoramas prefiltered this frame.
    pub prefiltered: u32,
    /// CPU time to record and submit them, in milliseconds (the GPU's time is in the frame's
    /// GPU total, as the work shares its queue).
    pub prefilter_cpu_ms: f64,
    /// Views that named a panorama the frame's snapshot does not hold: drawn without it.
    pub missing: u32,
    /// Prefiltered environments on the GPU after the frame.
    pub resident: u32,
    /// Whether any view named a panorama this frame.
    pub named: bool,
}

/// The prefiltered environments and their shared lookup table and sampler.
pub struct EnvironmentMaps {
    pipelines: Option<FilterPipelines>,
    sampler: Option<wgpu::Sampler>,
    lut: Option<(u32, wgpu::TextureView)>,
    maps: Vec<Prefiltered>,
    frame: u64,
    generation: u64,
    /// This frame's prefiltering.
    pub report: EnvironmentReport,
}

impl Default for EnvironmentMaps {
    fn default() -> Self {
        EnvironmentMaps::new()
    }
}

impl EnvironmentMaps {
    /// No environment yet: nothing on the GPU.
    pub fn new() -> EnvironmentMaps {
        EnvironmentMaps {
            pipelines: None,
            sampler: None,
            lut: None,
            maps: Vec::new(),
            frame: 0,
            generation: 0,
            report: EnvironmentReport::default(),
        }
    }

    /// Prefilters the panoramas the frame's views name that are not on the GPU yet (with the
    /// frame's [`EnvironmentFilter`]) and frees those no view has named for
    /// [`ENVIRONMENT_KEEP_FRAMES`] frames.
    pub fn prepare(&mut self, gpu: &GpuContext, snapshot: &FrameSnapshot) -> Result<(), RenderError> {
        self.frame += 1;
        self.report = EnvironmentReport::default();
        let filter = snapshot.settings.render.environment_filter;
        for view in &snapshot.views {
            let named = [view.camera.environment.map(|e| e.image), view.camera.skybox.map(|s| s.image)];
            for handle in named.into_iter().flatten() {
                self.report.named = true;
                if let Some(map) = self.maps.iter_mut().find(|m| m.handle == handle && m.filter == filter) {
                    map.last_used = self.frame;
                    continue;
                }
                let Some(image) = snapshot.environments.get(handle) else {
                    self.report.missing += 1;
                    continue;
                };
                let start = Instant::now();
                let map = self.prefilter(gpu, handle, image, filter)?;
                self.maps.push(map);
                self.report.prefiltered += 1;
                self.report.prefilter_cpu_ms += start.elapsed().as_secs_f64() * 1e3;
            }
        }
        let frame = self.frame;
        self.maps.retain(|m| frame - m.last_used <= ENVIRONMENT_KEEP_FRAMES);
        if self.maps.is_empty() {
            // Nothing names an environment: keep no table either.
            self.lut = None;
        }
        self.report.resident = self.maps.len() as u32;
        Ok(())
    }

    /// The bindings of `handle` prefiltered with `filter`, once [`EnvironmentMaps::prepare`]
    /// made them.
    pub fn bindings(
        &self,
        handle: EnvironmentHandle,
        filter: EnvironmentFilter,
    ) -> Option<EnvironmentBindings<'_>> {
        let map = self.maps.iter().find(|m| m.handle == handle && m.filter == filter)?;
        Some(EnvironmentBindings {
            specular: &map.specular,
            irradiance: &map.irradiance,
            lut: &self.lut.as_ref()?.1,
            sampler: self.sampler.as_ref()?,
            generation: map.generation,
        })
    }

    /// The specular cube of `handle` (its mip 0 is the panorama itself) and the sampler, for
    /// the skybox.
    pub fn sky(
        &self,
        handle: EnvironmentHandle,
        filter: EnvironmentFilter,
    ) -> Option<(&wgpu::TextureView, &wgpu::Sampler)> {
        let map = self.maps.iter().find(|m| m.handle == handle && m.filter == filter)?;
        Some((&map.specular, self.sampler.as_ref()?))
    }

    /// Prefiltered environments on the GPU.
    pub fn resident(&self) -> usize {
        self.maps.len()
    }

    fn prefilter(
        &mut self,
        gpu: &GpuContext,
        handle: EnvironmentHandle,
        image: &EquirectImage,
        filter: EnvironmentFilter,
    ) -> Result<Prefiltered, RenderError> {
        check_image(gpu, image)?;
        if self.pipelines.is_none() {
            self.pipelines = Some(FilterPipelines::new(gpu)?);
        }
        let sampler = self.sampler.get_or_insert_with(|| trilinear_sampler(&gpu.device)).clone();
        let pipelines = self.pipelines.as_ref().expect("created above");
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("environment prefilter") });
        if self.lut.as_ref().is_none_or(|(size, _)| *size != filter.lut_size) {
            let lut = record_lut(gpu, pipelines, &mut encoder, filter.lut_size);
            self.lut = Some((filter.lut_size, lut));
        }
        let recorder = Recorder { gpu, pipelines, sampler: &sampler };
        let source = recorder.source_cube(&mut encoder, image, filter.cube_size);
        let specular = recorder.specular_cube(&mut encoder, &source, filter);
        let irradiance = recorder.irradiance_cube(&mut encoder, &source, filter);
        gpu.queue.submit([encoder.finish()]);
        self.generation += 1;
        Ok(Prefiltered {
            handle,
            filter,
            specular: specular.create_view(&cube_view(0, None)),
            irradiance: irradiance.create_view(&cube_view(0, None)),
            last_used: self.frame,
            generation: self.generation,
        })
    }
}

/// Refuses a panorama the device cannot hold as one texture, or one too small to be a
/// panorama, naming its size.
fn check_image(gpu: &GpuContext, image: &EquirectImage) -> Result<(), RenderError> {
    let max = gpu.max_texture_size();
    let texels = image.width as usize * image.height as usize;
    if image.width < 2
        || image.height < 2
        || image.width > max
        || image.height > max
        || image.texels.len() != texels
    {
        return Err(RenderError::UnsupportedSettings(format!(
            "an environment panorama of {}x{} texels ({} given) cannot be uploaded: 2 to {max} texels a side",
            image.width,
            image.height,
            image.texels.len()
        )));
    }
    Ok(())
}

fn trilinear_sampler(device: &wgpu::Device) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("environment"),
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}

/// A cube view of mips `base..base + count` (all from `base` when `count` is `None`).
fn cube_view(base: u32, count: Option<u32>) -> wgpu::TextureViewDescriptor<'static> {
    wgpu::TextureViewDescriptor {
        label: Some("environment cube"),
        dimension: Some(wgpu::TextureViewDimension::Cube),
        base_mip_level: base,
        mip_level_count: count,
        ..Default::default()
    }
}

/// The six faces of mip `level`, for writing from compute.
fn faces_view(texture: &wgpu::Texture, level: u32) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some("environment faces"),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        base_mip_level: level,
        mip_level_count: Some(1),
        ..Default::default()
    })
}

fn cube_texture(device: &wgpu::Device, label: &str, size: u32, mips: u32) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 6 },
        mip_level_count: mips,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: ENVIRONMENT_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING,
        view_formats: &[],
    })
}

impl FilterPipelines {
    fn new(gpu: &GpuContext) -> Result<FilterPipelines, RenderError> {
        let device = &gpu.device;
        let defs = crate::shaders::ShaderDefs::default();
        let from_equirect_layout = ENV_FROM_EQUIRECT_GROUP.create_layout(device, defs);
        let filter_layout = ENV_FILTER_GROUP.create_layout(device, defs);
        let lut_layout = ENV_LUT_GROUP.create_layout(device, defs);
        let make = |entry: &str, layout: &GroupLayout| {
            crate::layouts::compute_pipeline(
                device,
                entry,
                "environment_prefilter.wgsl",
                &[layout],
                entry,
                &[],
            )
        };
        Ok(FilterPipelines {
            from_equirect: make("cs_from_equirect", &from_equirect_layout)?,
            downsample: make("cs_downsample", &filter_layout)?,
            specular: make("cs_specular", &filter_layout)?,
            irradiance: make("cs_irradiance", &filter_layout)?,
            lut: make("cs_brdf_lut", &lut_layout)?,
            from_equirect_layout,
            filter_layout,
            lut_layout,
        })
    }
}

fn params_buffer(gpu: &GpuContext, params: GpuEnvironmentFilter) -> wgpu::Buffer {
    gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("environment filter params"),
        contents: bytemuck::bytes_of(&params),
        usage: wgpu::BufferUsages::UNIFORM,
    })
}

fn dispatch(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    group: &wgpu::BindGroup,
    size: u32,
    layers: u32,
) {
    let mut pass = encoder
        .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, group, &[]);
    pass.dispatch_workgroups(size.div_ceil(8), size.div_ceil(8), layers);
}

fn record_lut(
    gpu: &GpuContext,
    pipelines: &FilterPipelines,
    encoder: &mut wgpu::CommandEncoder,
    size: u32,
) -> wgpu::TextureView {
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("environment brdf lut"),
        size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: ENVIRONMENT_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    let params =
        params_buffer(gpu, GpuEnvironmentFilter { size, samples: LUT_SAMPLES, ..Default::default() });
    let group =
        pipelines.lut_layout.create_bind_group(gpu, &[Binding::Buffer(&params), Binding::Texture(&view)]);
    dispatch(encoder, "environment lut", &pipelines.lut, &group, size, 1);
    view
}

/// Records the dispatches of one panorama.
struct Recorder<'a> {
    gpu: &'a GpuContext,
    pipelines: &'a FilterPipelines,
    sampler: &'a wgpu::Sampler,
}

impl Recorder<'_> {
    /// Writes `target`'s mip `level` (a face of `size`) from `source` (a cube view) with
    /// `pipeline`.
    #[allow(clippy::too_many_arguments)]
    fn filter_into(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        pipeline: &wgpu::ComputePipeline,
        source: &wgpu::TextureView,
        target: &wgpu::Texture,
        level: u32,
        params: GpuEnvironmentFilter,
    ) {
        let buffer = params_buffer(self.gpu, params);
        let out = faces_view(target, level);
        let group = self.pipelines.filter_layout.create_bind_group(
            self.gpu,
            &[
                Binding::Buffer(&buffer),
                Binding::Texture(source),
                Binding::Sampler(self.sampler),
                Binding::Texture(&out),
            ],
        );
        dispatch(encoder, label, pipeline, &group, params.size, 6);
    }

    /// The panorama as a cube with every mip, each the mean of the four texels above it.
    fn source_cube(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        image: &EquirectImage,
        size: u32,
    ) -> wgpu::Texture {
        let gpu = self.gpu;
        let equirect = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("environment panorama"),
            size: wgpu::Extent3d { width: image.width, height: image.height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let texels: Vec<[f32; 4]> = image.texels.iter().map(|&[r, g, b]| [r, g, b, 1.0]).collect();
        gpu.write_texture(
            equirect.as_image_copy(),
            bytemuck::cast_slice(&texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(image.width * 16),
                rows_per_image: None,
            },
            equirect.size(),
        );
        let mips = size.ilog2() + 1;
        let cube = cube_texture(&gpu.device, "environment source", size, mips);
        // Reads per axis: enough that each cube texel averages every panorama texel it covers
        // (a face spans a quarter of the panorama's width).
        let reads = image.width.div_ceil(4 * size).clamp(1, 8);
        let params = params_buffer(
            gpu,
            GpuEnvironmentFilter {
                size,
                samples: reads,
                equirect_width: image.width,
                equirect_height: image.height,
                ..Default::default()
            },
        );
        let equirect_view = equirect.create_view(&Default::default());
        let out = faces_view(&cube, 0);
        let group = self.pipelines.from_equirect_layout.create_bind_group(
            gpu,
            &[Binding::Buffer(&params), Binding::Texture(&equirect_view), Binding::Texture(&out)],
        );
        dispatch(encoder, "environment from panorama", &self.pipelines.from_equirect, &group, size, 6);
        for level in 1..mips {
            let above = cube.create_view(&cube_view(level - 1, Some(1)));
            let params = GpuEnvironmentFilter { size: size >> level, ..Default::default() };
            self.filter_into(
                encoder,
                "environment downsample",
                &self.pipelines.downsample,
                &above,
                &cube,
                level,
                params,
            );
        }
        cube
    }

    /// The specular cube: mip 0 the source's (roughness 0 reflects the panorama itself), mip m
    /// the source convolved with GGX at [`EnvironmentFilter::specular_mip_roughness`],
    /// `(m / (mips - 1))²`, the roughness the shading passes' lod maps back to.
    fn specular_cube(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::Texture,
        filter: EnvironmentFilter,
    ) -> wgpu::Texture {
        let mips = filter.specular_mips();
        let size = filter.cube_size;
        let specular = cube_texture(&self.gpu.device, "environment specular", size, mips);
        let top = source.create_view(&cube_view(0, Some(1)));
        let copy = GpuEnvironmentFilter { size, ..Default::default() };
        self.filter_into(
            encoder,
            "environment specular",
            &self.pipelines.downsample,
            &top,
            &specular,
            0,
            copy,
        );
        let all = source.create_view(&cube_view(0, None));
        for level in 1..mips {
            let params = GpuEnvironmentFilter {
                size: size >> level,
                samples: filter.samples,
                roughness: filter.specular_mip_roughness(level),
                source_size: size as f32,
                source_max_lod: (source.mip_level_count() - 1) as f32,
                ..Default::default()
            };
            self.filter_into(
                encoder,
                "environment specular",
                &self.pipelines.specular,
                &all,
                &specular,
                level,
                params,
            );
        }
        specular
    }

    /// The irradiance cube.
    fn irradiance_cube(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::Texture,
        filter: EnvironmentFilter,
    ) -> wgpu::Texture {
        let irradiance = cube_texture(&self.gpu.device, "environment irradiance", filter.irradiance_size, 1);
        let all = source.create_view(&cube_view(0, None));
        let params = GpuEnvironmentFilter {
            size: filter.irradiance_size,
            samples: filter.samples,
            source_size: filter.cube_size as f32,
            source_max_lod: (source.mip_level_count() - 1) as f32,
            ..Default::default()
        };
        self.filter_into(
            encoder,
            "environment irradiance",
            &self.pipelines.irradiance,
            &all,
            &irradiance,
            0,
            params,
        );
        irradiance
    }
}
