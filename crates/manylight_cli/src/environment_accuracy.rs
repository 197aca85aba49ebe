//! How far split-sum image-based lighting is from the integral it approximates
//! (`manylight environment-accuracy`), and what its prefilter costs.
//!
//! 1. **Scene** ([`spheres`]): two rows of spheres (metal, dielectric) of roughness 0.05 to 1,
//!    an orthographic camera, no light, no ambient term, a black clear colour, no skybox; the
//!    panorama lights them through the camera's `EnvironmentMapLight`.
//! 2. **Reference** ([`reference::radiance`]): each pixel centre's ray is cast at the spheres
//!    on the CPU; pixels within one pixel of an outline are left out (there the mesh's polygon
//!    and the circle differ). Each kept pixel is integrated twice, with two seeds, sampling
//!    the BRDF and the panorama: their mean is the reference, their difference its noise.
//!    Core's `reference_radiance` (BRDF sampling only) is measured against it too.
//! 3. **Split-sum on the CPU**: core's twin `split_sum_radiance` at 1,024 samples a factor
//!    (the GPU's sampling without its cubes and table), and the split-sum with every factor
//!    integrated as exactly as the reference ([`reference::split_sum`]): the approximation's
//!    own error.
//! 4. **GPU**: for each prefilter setting of the three sweeps (samples, cube size, table size)
//!    the renderer draws the spheres; its HDR image is read back before the tone map
//!    ([`capture`]).
//! 5. **Error** ([`error`]): FLIP of the tone-mapped images and the luminance-weighted mean
//!    relative error `sum |gpu - ref| / sum ref`, per sphere, per range of `n.v` and on each
//!    sphere's highlights.
//! 6. **Cost**: a panorama is prefiltered in the first frame that names it, so the prefilter
//!    time is that frame's wall time less a steady frame's (the renderer waits for the GPU in
//!    both); each setting starts from a lookup table of another size and a new panorama
//!    handle, so the table and every cube are made again. The per-frame cost is the steady
//!    frame with the environment against the same frame without it (medians, interleaved).

mod capture;
pub mod error;
pub mod figure;
pub mod reference;
pub mod spheres;
pub mod table;

use anyhow::{Context, Result};
use error::ImageError;
use glam::{UVec2, Vec3};
use manylight_app::render_world::HeadlessRenderer;
use manylight_core::ShadingModel;
use manylight_core::environment::split_sum::{SplitSumSamples, split_sum_radiance};
use manylight_core::environment::{EquirectImage, reference_radiance};
use manylight_render::{
    EnvironmentFilter, EnvironmentHandle, EnvironmentImages, EnvironmentMapLight, FramePlanner,
    FrameSettings, FrameSnapshot, PipelineKind,
};
use rayon::prelude::*;
use reference::EnvironmentSampler;
use spheres::Spheres;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// What to measure.
pub struct Options {
    /// The panorama file.
    pub environment: PathBuf,
    /// Image size.
    pub size: UVec2,
    /// Samples per pixel of each reference (each draws a GGX, a cosine and an environment
    /// direction).
    pub reference_samples: u32,
    /// Timed frames per setting, with and without the environment.
    pub frames: u32,
}

/// Samples per factor of the CPU twin.
pub const TWIN_SAMPLES: u32 = 1024;

/// Which parameter a sweep varies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sweep {
    /// GGX samples per texel, cube 256, table 128.
    Samples,
    /// Cube face size, 1,024 samples, table 128.
    CubeSize,
    /// Lookup-table size, cube 256, 1,024 samples.
    LutSize,
}

impl Sweep {
    /// Every sweep, in table order.
    pub const ALL: [Sweep; 3] = [Sweep::Samples, Sweep::CubeSize, Sweep::LutSize];

    /// Its name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Sweep::Samples => "samples",
            Sweep::CubeSize => "cube size",
            Sweep::LutSize => "LUT size",
        }
    }

    /// Its settings, in rising order of the parameter.
    pub fn filters(self) -> Vec<EnvironmentFilter> {
        let base = EnvironmentFilter { cube_size: 256, samples: 1024, irradiance_size: 32, lut_size: 128 };
        match self {
            Sweep::Samples => {
                [64, 256, 1024, 4096].map(|samples| EnvironmentFilter { samples, ..base }).to_vec()
            }
            Sweep::CubeSize => {
                [64, 128, 256, 512].map(|cube_size| EnvironmentFilter { cube_size, ..base }).to_vec()
            }
            Sweep::LutSize => {
                [16, 32, 64, 128].map(|lut_size| EnvironmentFilter { lut_size, ..base }).to_vec()
            }
        }
    }

    /// The value it varies in `filter`.
    pub fn value(self, filter: &EnvironmentFilter) -> u32 {
        match self {
            Sweep::Samples => filter.samples,
            Sweep::CubeSize => filter.cube_size,
            Sweep::LutSize => filter.lut_size,
        }
    }
}

/// What one prefilter setting costs on the device.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cost {
    /// Wall time of the panorama's first frame less a steady frame's, ms.
    pub prefilter_ms: f64,
    /// The CPU part of it: recording and submitting the dispatches, ms.
    pub prefilter_cpu_ms: f64,
    /// Median steady frame with the environment, ms.
    pub frame_ms: f64,
    /// Median steady frame without it, ms.
    pub plain_frame_ms: f64,
}

impl Cost {
    /// The prefilter in frames without the environment.
    pub fn prefilter_frames(&self) -> f64 {
        self.prefilter_ms / self.plain_frame_ms
    }

    /// The frame with the environment over the frame without.
    pub fn frame_ratio(&self) -> f64 {
        self.frame_ms / self.plain_frame_ms
    }
}

/// One GPU prefilter setting, measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuRow {
    /// The setting.
    pub filter: EnvironmentFilter,
    /// Its image against the reference.
    pub error: ImageError,
    /// What it costs.
    pub cost: Cost,
}

/// Everything `environment-accuracy` measured.
pub struct Measurement {
    /// The panorama's file name.
    pub environment: String,
    /// Image size.
    pub size: UVec2,
    /// The adapter's name.
    pub adapter: String,
    /// Samples per pixel of each reference.
    pub reference_samples: u32,
    /// Sphere pixels kept, and pixels that see a sphere at all.
    pub pixels: (usize, usize),
    /// The two references against each other: the reference's own noise.
    pub noise: ImageError,
    /// Core's `reference_radiance` (BRDF sampling only, as many samples) against the reference.
    pub core_reference: ImageError,
    /// Core's split-sum twin at [`TWIN_SAMPLES`] against the reference.
    pub twin: ImageError,
    /// The split-sum with exact factors against the reference: the approximation's own error.
    pub exact_split_sum: ImageError,
    /// Every GPU setting, each once (the sweeps share their middle setting).
    pub gpu: Vec<GpuRow>,
    /// Wall time of each phase in seconds: the references, core's reference, the two CPU
    /// split-sums, the GPU settings.
    pub seconds: [f64; 4],
}

impl Measurement {
    /// The row of `filter`.
    pub fn row(&self, filter: &EnvironmentFilter) -> Option<&GpuRow> {
        self.gpu.iter().find(|r| r.filter == *filter)
    }
}

/// Runs the measurement (see the module's steps).
pub fn measure(options: &Options) -> Result<Measurement> {
    let decoded = manylight_scene::load_environment(
        &options.environment,
        &manylight_scene::EnvironmentBudget::default(),
    )?;
    let panorama = Arc::new(decoded.image);
    let spheres = Spheres::new(options.size);
    anyhow::ensure!(
        !spheres.hits.is_empty(),
        "at {}x{} no pixel sees a sphere",
        options.size.x,
        options.size.y
    );
    let size = (options.size.x, options.size.y);

    let sampler =
        EnvironmentSampler::new(&panorama).context("the panorama is black: nothing lights the spheres")?;
    let samples = options.reference_samples;
    let cpu = |name: &str, f: &(dyn Fn(&spheres::Hit) -> Vec3 + Sync)| {
        let start = Instant::now();
        let image: Vec<Vec3> = spheres.hits.par_iter().map(f).collect();
        eprintln!("{name}: {:.0} s", start.elapsed().as_secs_f64());
        image
    };
    eprintln!(
        "{} sphere pixels, {samples} samples each, on {} threads",
        spheres.hits.len(),
        rayon::current_num_threads()
    );
    let start = Instant::now();
    let (panorama_ref, sampler_ref) = (&*panorama, &sampler);
    let seeded = |offset: u64| {
        move |h: &spheres::Hit| {
            let seed = h.pixel as u64 + offset;
            reference::radiance(panorama_ref, sampler_ref, (h.normal, h.view), &h.surface(), samples, seed)
        }
    };
    let first = cpu("reference, first seed", &seeded(0));
    let second = cpu("reference, second seed", &seeded(1 << 40));
    let reference: Vec<Vec3> = first.iter().zip(&second).map(|(a, b)| (*a + *b) * 0.5).collect();
    let noise = error::measure(size, &spheres.hits, &second, &first)?;
    let reference_seconds = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let core = cpu("core reference_radiance", &|h| {
        reference_radiance(&panorama, h.normal, h.view, &h.surface(), samples, h.pixel as u64 + (2 << 40))
    });
    let core_reference = error::measure(size, &spheres.hits, &core, &reference)?;
    let core_seconds = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let twin_samples =
        SplitSumSamples { lut: TWIN_SAMPLES, specular: TWIN_SAMPLES, irradiance: TWIN_SAMPLES };
    let twin_image = cpu("core split-sum twin", &|h| {
        split_sum_radiance(&panorama, h.normal, h.view, &h.surface(), twin_samples)
    });
    let twin = error::measure(size, &spheres.hits, &twin_image, &reference)?;
    let weights = spheres::ROUGHNESS.map(reference::prefilter_weight);
    let exact_image = cpu("split-sum with exact factors", &|h| {
        let factor = (samples, weights[h.column]);
        reference::split_sum(&panorama, &sampler, (h.normal, h.view), &h.surface(), factor, h.pixel as u64)
    });
    let exact_split_sum = error::measure(size, &spheres.hits, &exact_image, &reference)?;
    let split_sum_seconds = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let mut device = Device::new(&spheres, panorama)?;
    let mut filters: Vec<EnvironmentFilter> = Vec::new();
    for filter in Sweep::ALL.iter().flat_map(|s| s.filters()) {
        if !filters.contains(&filter) {
            filters.push(filter);
        }
    }
    let mut progress = crate::progress::Progress::new(filters.len() as u64, "prefilter settings");
    let mut gpu = Vec::new();
    for filter in filters {
        progress.set_message(label(&filter));
        let (image, cost) = device.measure(filter, options.frames.max(1))?;
        let gpu_radiance: Vec<Vec3> = spheres.hits.iter().map(|h| image[h.pixel]).collect();
        let error = error::measure(size, &spheres.hits, &gpu_radiance, &reference)?;
        progress.step(|| {
            format!(
                "{}: FLIP {:.4}, {:.2}% off, prefilter {:.0} ms",
                label(&filter),
                error.flip.mean,
                100.0 * error.all().relative(),
                cost.prefilter_ms
            )
        });
        gpu.push(GpuRow { filter, error, cost });
    }
    progress.finish();
    Ok(Measurement {
        environment: options
            .environment
            .file_name()
            .map_or_else(|| options.environment.display().to_string(), |n| n.to_string_lossy().into_owned()),
        size: options.size,
        adapter: device.adapter,
        reference_samples: options.reference_samples,
        pixels: (spheres.hits.len(), spheres.covered),
        noise,
        core_reference,
        twin,
        exact_split_sum,
        gpu,
        seconds: [reference_seconds, core_seconds, split_sum_seconds, start.elapsed().as_secs_f64()],
    })
}

/// A setting's label: cube size, samples, table size.
pub fn label(filter: &EnvironmentFilter) -> String {
    format!("cube {}, {} samples, LUT {}", filter.cube_size, filter.samples, filter.lut_size)
}

/// The renderer and what every frame of the measurement shares.
struct Device {
    renderer: HeadlessRenderer,
    adapter: String,
    scene: manylight_scene::Scene,
    size: UVec2,
    panorama: Arc<EquirectImage>,
    /// Mints a new handle for each prefilter, so every setting prefilters anew.
    handles: EnvironmentImages,
    plain_stages: Arc<FramePlanner>,
    capturing_stages: Arc<FramePlanner>,
    frame: u64,
}

/// The smallest prefilter there is: it resets the lookup table to a size no setting uses.
const RESET: EnvironmentFilter =
    EnvironmentFilter { cube_size: 16, samples: 1, irradiance_size: 4, lut_size: 8 };

impl Device {
    /// A renderer that has drawn the spheres once with and once without an environment, and
    /// once capturing (so no timed frame compiles a pipeline).
    fn new(spheres: &Spheres, panorama: Arc<EquirectImage>) -> Result<Device> {
        let renderer = HeadlessRenderer::new()?;
        let adapter = renderer.render_world.gpu().info.name.clone();
        let mut device = Device {
            renderer,
            adapter,
            scene: spheres.scene(),
            size: spheres.size,
            panorama,
            handles: EnvironmentImages::default(),
            plain_stages: Arc::new(FramePlanner::default()),
            capturing_stages: capture::capturing_stages()?,
            frame: 0,
        };
        device.renderer.render_world.set_stages(&device.plain_stages);
        let handle = device.handles.add(device.panorama.clone());
        for environment in [None, Some(handle), Some(handle), None] {
            device.render(RESET, environment)?;
        }
        device.renderer.render_world.set_stages(&device.capturing_stages);
        device.render(RESET, Some(handle))?;
        capture::read(device.renderer.render_world.gpu())?;
        Ok(device)
    }

    /// The snapshot of the spheres with `filter`, lit by the panorama of `environment`.
    fn snapshot(
        &mut self,
        filter: EnvironmentFilter,
        environment: Option<EnvironmentHandle>,
    ) -> FrameSnapshot {
        let mut settings = FrameSettings::default();
        settings.render.pipeline = PipelineKind::NaiveForward;
        settings.render.shading = ShadingModel::Pbr;
        settings.render.ambient = 0.0;
        settings.render.clear_color = [0.0; 3];
        settings.render.exposure = error::EXPOSURE;
        settings.render.environment_filter = filter;
        self.frame += 1;
        let mut snapshot =
            manylight_app::scene::scene_snapshot(&self.scene, Vec::new(), self.size, settings, self.frame);
        if let Some(handle) = environment {
            snapshot.environments.insert(handle, self.panorama.clone());
            if let Some(camera) = snapshot.camera_mut() {
                camera.environment = Some(EnvironmentMapLight::new(handle));
            }
        }
        snapshot
    }

    /// Renders one frame and returns its wall time in ms (the renderer waits for the GPU).
    fn render(&mut self, filter: EnvironmentFilter, environment: Option<EnvironmentHandle>) -> Result<f64> {
        let snapshot = self.snapshot(filter, environment);
        let start = Instant::now();
        self.renderer.render(snapshot, false)?;
        Ok(start.elapsed().as_secs_f64() * 1e3)
    }

    /// Prefilters the panorama with `filter` (timed), times `frames` steady frames with and
    /// without it, and returns the HDR image of one more frame with it.
    fn measure(&mut self, filter: EnvironmentFilter, frames: u32) -> Result<(Vec<Vec3>, Cost)> {
        self.renderer.render_world.set_stages(&self.plain_stages);
        let reset = self.handles.add(self.panorama.clone());
        self.render(RESET, Some(reset))?;
        self.render(RESET, None)?;
        let handle = self.handles.add(self.panorama.clone());
        let first_ms = self.render(filter, Some(handle))?;
        let environments = &self.renderer.render_world.renderer().environments;
        anyhow::ensure!(
            environments.report.prefiltered == 1,
            "the first frame did not prefilter the panorama"
        );
        let prefilter_cpu_ms = environments.report.prefilter_cpu_ms;
        let (mut with, mut without) = (Vec::new(), Vec::new());
        for _ in 0..frames {
            with.push(self.render(filter, Some(handle))?);
            without.push(self.render(filter, None)?);
        }
        let (frame_ms, plain_frame_ms) = (median(&mut with), median(&mut without));
        self.renderer.render_world.set_stages(&self.capturing_stages);
        self.render(filter, Some(handle))?;
        let image = capture::read(self.renderer.render_world.gpu()).context("reading the HDR image back")?;
        let pixels = self.size.x as usize * self.size.y as usize;
        anyhow::ensure!(image.len() == pixels, "read back {} HDR pixels of {pixels}", image.len());
        let cost = Cost { prefilter_ms: first_ms - frame_ms, prefilter_cpu_ms, frame_ms, plain_frame_ms };
        Ok((image, cost))
    }
}

/// The median of `values` (sorted in place); 0 for none.
fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    match values.len() {
        0 => 0.0,
        n if n % 2 == 1 => values[n / 2],
        n => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}
