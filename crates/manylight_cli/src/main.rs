//! `manylight`: render a scene to PNG, check a glTF file, benchmark pipelines, and measure
//! what accuracy and post stages cost, with tables, CSV and plots.
#![warn(missing_docs)]

use anyhow::{Context, Result, bail};
use bevy_app::Startup;
use bevy_ecs::system::Commands;
use clap::{Parser, Subcommand};
use glam::{UVec2, UVec3};
use manylight_app::FrameStats;
use manylight_app::RenderSettings;
use manylight_app::cli::{
    parse_ambient, parse_bloom_chain, parse_cull, parse_debug_view, parse_ev100, parse_exposure,
    parse_gbuffer, parse_grid, parse_normal_codec, parse_on_off, parse_pipeline, parse_redraw_budget,
    parse_shading, parse_size, parse_slicing,
};
use manylight_app::headless::{render_headless, save_png};
use manylight_app::scene::{spawn_light_rig, spawn_scene};
use manylight_core::ShadingModel;
use manylight_core::cluster::{CullTest, GridConfig, ZSlicing};
use manylight_core::codec::NormalCodec;
use manylight_render::{BloomChain, ClusterSettings, DebugViewMode, GBufferLayout, PipelineKind};
use manylight_scene::{LoadOptions, Scene, load_scene};
use std::path::PathBuf;
use std::process::ExitCode;

mod bench;
mod codec_accuracy;
mod culling_tests;
mod depth_precision;
mod direct;
mod large_floor;
mod plot;
mod post;
mod progress;
mod report;
use report::Report;
mod shadow_error;
mod soak;
mod views;

#[derive(Parser)]
#[command(name = "manylight", version, about = "Many-light rendering with wgpu: render, check, bench")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene headless and write the last frame as PNG.
    Render(RenderArgs),
    /// Load a glTF/GLB file and render one frame headless; exit 1 with the error on bad input.
    Check {
        /// The .gltf or .glb file.
        path: PathBuf,
    },
    /// Sweep pipelines × light counts at one size and write the timings as CSV.
    Bench(BenchArgs),
    /// What accuracy costs in time: every pipeline and G-buffer layout against the naive
    /// reference (FLIP) and its frame time, in one run, as a markdown table; then what cutting
    /// off lights without a range costs against their unbounded sum.
    Report(ReportArgs),
    /// Only the last table of `report`: lights without a range cut off at several fractions of
    /// their intensity (clustered forward) against their unbounded sum (naive forward).
    RangelessLights(ReportArgs),
    /// What bloom and motion blur cost per frame: the same frame without post stages, with
    /// each bloom chain, with motion blur and with both, in one run, as a markdown table.
    Post(ReportArgs),
    /// What several cameras cost: the same pixels as 1, 2 and 4 views (each with its own
    /// clusters; lights uploaded once per frame), in one run, as a markdown table.
    Views(ViewsArgs),
    /// Thousands of frames in a window while sizes, post stages, debug views and the light
    /// count keep changing; exit 1 if memory or the transient pool grows, a frame fails or a
    /// pixel is NaN.
    Soak(soak::SoakArgs),
    /// Draw the figures of a CSV that `bench`, `report` or `post` wrote.
    Plot {
        /// The CSV file.
        csv: PathBuf,
        /// Folder for the PNG figures.
        #[arg(long)]
        out: PathBuf,
    },
    /// How accurately positions come back from a reverse-Z and a conventional f32 depth
    /// buffer, per decade of distance, as markdown tables (CPU only).
    DepthPrecision {
        /// Log-spaced depths per decade (each at five pixels).
        #[arg(long, default_value_t = 2000)]
        samples: usize,
    },
    /// False-positive rates of the sphere–cluster tests (AABB, planes, both) against an exact
    /// test, as a markdown table (CPU only).
    CullingTests {
        /// Random lights.
        #[arg(long, default_value_t = 1024)]
        lights: usize,
        /// Seed of the light placement.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Worst and mean angular error of every normal codec over the sphere, as a markdown
    /// table (CPU only).
    CodecAccuracy {
        /// Fibonacci points over the sphere.
        #[arg(long, default_value_t = 4_000_000)]
        samples: usize,
    },
}

#[derive(clap::Args)]
struct ReportArgs {
    /// `default`, `sphere-shell` or a .gltf/.glb path.
    #[arg(long, default_value = "default")]
    scene: String,
    /// Rig lights.
    #[arg(long, default_value_t = 1024)]
    lights: usize,
    /// Image size, WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    size: UVec2,
    /// Timed frames per configuration (after one warm-up).
    #[arg(long, default_value_t = 2)]
    frames: u32,
    #[command(flatten)]
    clusters: ClusterArgs,
    /// Also write the results as CSV and PNG figures into this folder.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// The shadow section instead (`report`): shadow settings — none, atlas sizes, resolution
    /// policies, redraw budgets with moving lights, caching with still ones — every light
    /// casting, each with its frame time, visibility error and FLIP against the shadow
    /// reference (`report_shadows.csv` and its figures with `--plot`).
    #[arg(long)]
    shadows: bool,
    /// The very-large-surfaces section instead (`report`): a floor quad with corners at ±extent
    /// under four point lights, flat and tilted, drawn by every pipeline, G-buffer layout and
    /// normal codec at `--size` against the same floor tessellated into rings that grow with the
    /// distance from the camera (naive forward), and those rings against the floor shaded
    /// analytically on the CPU: FLIP mean and p99, worst 8-bit channel and non-finite pixels,
    /// one frame each, as a markdown table. Draws its own floor: no scene, rig lights or timing.
    #[arg(long, conflicts_with_all = ["shadows", "plot", "scene", "lights", "frames"])]
    large_floor: bool,
    /// Half-sizes of the floor `--large-floor` measures (`report`).
    #[arg(long, value_delimiter = ',', default_value = "10,1e4,1e7", requires = "large_floor",
          value_parser = large_floor::parse_extent)]
    floor_extents: Vec<f64>,
    /// Far plane of `--large-floor`'s camera, or `inf` for none (`report`).
    #[arg(long, default_value = "1e8", requires = "large_floor", value_parser = large_floor::parse_far)]
    floor_far: f32,
}

#[derive(clap::Args)]
struct ViewsArgs {
    /// `default`, `sphere-shell` or a .gltf/.glb path.
    #[arg(long, default_value = "default")]
    scene: String,
    /// Rig lights.
    #[arg(long, default_value_t = 1024)]
    lights: usize,
    /// Size of the whole target, WxH (the views split it).
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    size: UVec2,
    /// Timed frames per view count (after one warm-up).
    #[arg(long, default_value_t = 5)]
    frames: u32,
    #[command(flatten)]
    clusters: ClusterArgs,
}

#[derive(clap::Args)]
struct BenchArgs {
    /// `default`, `sphere-shell` or a .gltf/.glb path.
    #[arg(long, default_value = "default")]
    scene: String,
    /// Comma-separated pipelines.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "naive,forward-plus,clustered-forward,clustered-deferred",
        value_parser = parse_pipeline
    )]
    pipelines: Vec<PipelineKind>,
    /// Comma-separated rig light counts.
    #[arg(long, value_delimiter = ',', default_value = "16,64,256,1024,4096,16384")]
    lights: Vec<usize>,
    /// Image size, WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    size: UVec2,
    /// Frames measured per configuration (the median is reported).
    #[arg(long, default_value_t = 3)]
    frames: u32,
    /// Frames rendered first and not measured (pipeline creation, uploads).
    #[arg(long, default_value_t = 1)]
    warmup: u32,
    /// Skip naive forward above this many lights (it costs seconds per frame on a CPU).
    #[arg(long, default_value_t = 1024)]
    naive_max_lights: usize,
    /// Also measure each tiled/clustered configuration's culling efficiency.
    #[arg(long)]
    culling_efficiency: bool,
    /// Also render each light count's frames with exact per-pixel light lists built on the CPU
    /// from the read-back depth (not timed): the floor of culling. Every row gets its shading
    /// time against the oracle's (`shading_vs_oracle`).
    #[arg(long)]
    oracle: bool,
    /// G-buffer layouts swept for the deferred pipelines (clustered-deferred, tiled-deferred,
    /// light-volumes).
    #[arg(long, value_delimiter = ',', default_value = "full,compact", value_parser = parse_gbuffer)]
    gbuffers: Vec<GBufferLayout>,
    /// Comma-separated shadow settings swept: `off` (no light casts), `on` (every light of the
    /// scene and the rig casts).
    #[arg(long, value_delimiter = ',', default_value = "off", value_parser = parse_on_off, action = clap::ArgAction::Set)]
    shadows: Vec<bool>,
    /// Also measure each pipeline row's last frame against exact visibility: the CSV columns
    /// `visibility_error` (mean |shadow test - exact| over the light-pixel pairs the light
    /// reaches) and `flip_vs_shadow_reference` (FLIP mean against naive forward with exact
    /// visibility). Not timed.
    #[arg(long)]
    shadow_oracle: bool,
    #[command(flatten)]
    shadow: ShadowArgs,
    #[command(flatten)]
    clusters: ClusterArgs,
    /// Shading model for materials without their own: pbr (default), lambert, blinn-phong or toon.
    #[arg(long, default_value = "pbr", value_parser = parse_shading)]
    shading: ShadingModel,
    /// CSV output.
    #[arg(long)]
    out: PathBuf,
    /// Also draw PNG figures of the CSV into this folder.
    #[arg(long)]
    plot: Option<PathBuf>,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// `default` (embedded hall), `sphere-shell`, or a path to a .gltf/.glb file.
    #[arg(long, default_value = "default")]
    scene: String,
    /// Pipeline: naive, forward-plus, clustered-forward, clustered-deferred, tiled-deferred or
    /// light-volumes.
    #[arg(long, default_value = "clustered-forward", value_parser = parse_pipeline)]
    pipeline: PipelineKind,
    #[command(flatten)]
    clusters: ClusterArgs,
    /// Shading model for materials without their own: pbr (default), lambert, blinn-phong or toon.
    #[arg(long, default_value = "pbr", value_parser = parse_shading)]
    shading: ShadingModel,
    /// Animated lights (inside the scene's bounds) added to the scene's own lights (default 0).
    /// For `sphere-shell`: the lights of its lattice instead (default 100 000).
    #[arg(long)]
    lights: Option<usize>,
    /// Static white lights on a dome around the scene, as a model viewer lights a model
    /// (default: 32 for a scene that brings no lights of its own and no `--lights`, so it is
    /// not black; 0 otherwise).
    #[arg(long)]
    studio_lights: Option<usize>,
    /// Image size, WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    size: UVec2,
    /// Frames to render (animation advances 1/60 s per frame); the last one is written.
    #[arg(long, default_value_t = 1)]
    frames: u32,
    /// Exposure multiplier before tone mapping.
    #[arg(long, default_value_t = 1.0, conflicts_with = "ev100", allow_hyphen_values = true, value_parser = parse_exposure)]
    exposure: f32,
    /// Photographic exposure value at ISO 100 instead of `--exposure` (multiplier
    /// 1 / (1.2 · 2^EV100)): about 15 for sunlight, 7 for a lamp-lit room, with lights in
    /// physical units.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_ev100)]
    ev100: Option<f32>,
    /// Constant ambient light, as a fraction of albedo (default: 0.03, or 0.2 for a scene
    /// that brings no lights of its own, so its shapes read).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_ambient)]
    ambient: Option<f32>,
    /// Seed of the light placement.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Camera: `scene` (the file's first camera, else a fitted one), `fit` (frame the whole
    /// scene), or the index of one of the file's cameras.
    #[arg(long, default_value = "scene")]
    camera: String,
    /// Shadows: `on` makes every light of the scene and of `--lights` cast one (glTF has no
    /// shadow flag), `off` (default) none.
    #[arg(long, default_value = "off", value_parser = parse_on_off, action = clap::ArgAction::Set)]
    shadows: bool,
    #[command(flatten)]
    shadow: ShadowArgs,
    /// Output PNG.
    #[arg(long)]
    out: PathBuf,
    /// Write the last frame's statistics as JSON here.
    #[arg(long)]
    stats_json: Option<PathBuf>,
    /// Measure the culling efficiency of the last frame: light-pixel pairs evaluated ÷ pairs
    /// with a non-zero contribution (CPU reference over the depth buffer read back).
    #[arg(long)]
    culling_efficiency: bool,
    /// Also time the shading of the last frame against the oracle's: the same frame shaded by
    /// clustered forward from exact per-pixel light lists built on the CPU (not timed) from
    /// its depth.
    #[arg(long)]
    oracle: bool,
    /// Also measure the last frame's shadows against exact visibility (a ray cast from every
    /// pixel's surface to each light that reaches it): prints the visibility error (mean
    /// |shadow test - exact| over those pairs) and FLIP against the shadow reference (the
    /// oracle's lists without the blocked pairs: naive forward with exact visibility).
    #[arg(long)]
    shadow_oracle: bool,
    /// Where `--shadow-oracle` writes the shadow reference image (PNG).
    #[arg(long, requires = "shadow_oracle")]
    shadow_reference: Option<PathBuf>,
    #[command(flatten)]
    post: PostArgs,
}

/// Opt-in post stages of `render`.
#[derive(clap::Args, Clone, Debug)]
struct PostArgs {
    /// Bloom on the camera.
    #[arg(long)]
    bloom: bool,
    /// Bloom chain: downsampled (halves the resolution per iteration) or full-resolution
    /// (separable 1×9/9×1 kernels, every iteration at full size).
    #[arg(long, default_value = "downsampled", value_parser = parse_bloom_chain)]
    bloom_chain: BloomChain,
    /// Camera-motion blur on the camera; the camera turns between frames so it shows (at least
    /// 2 frames are rendered).
    #[arg(long)]
    motion_blur: bool,
}

/// The shadow atlas and resolution policy (`manylight_render::ShadowSettings`).
#[derive(clap::Args, Clone, Debug)]
struct ShadowArgs {
    /// Largest edge of the shadow atlas in texels (a power of two).
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().atlas_size)]
    shadow_atlas: u32,
    /// Largest cube-face edge a point or spot light's shadow gets (a power of two).
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().max_face_size)]
    shadow_max_face: u32,
    /// Smallest cube-face edge (a power of two): below it a light goes without a shadow, counted.
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().min_face_size)]
    shadow_min_face: u32,
    /// Face texels asked per pixel of a light sphere's projected radius.
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().resolution_scale)]
    shadow_resolution_scale: f32,
    /// Edge of each cascade of a directional light (a power of two).
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().cascade_size)]
    shadow_cascade_size: u32,
    /// `on` (default): a light's map is kept from the frame before when neither the light nor
    /// the casters near it changed; `off`: every map is drawn every frame (the same image).
    #[arg(long, default_value = "on", value_parser = parse_on_off, action = clap::ArgAction::Set)]
    shadow_cache_maps: bool,
    /// Most point or spot light maps drawn again per frame when their light or casters changed,
    /// or `all`; the least important others keep an earlier frame's map, counted.
    #[arg(long, default_value = "256", value_parser = parse_redraw_budget)]
    shadow_max_redrawn_maps: manylight_app::cli::RedrawBudget,
    /// Filter of every shadow lookup: hardware2x2 (one bilinear comparison) or gaussian (four,
    /// a 3×3 tent).
    #[arg(long, default_value = "hardware2x2", value_parser = manylight_app::cli::parse_shadow_filter)]
    shadow_filter: manylight_render::ShadowFilteringMethod,
}

impl ShadowArgs {
    /// The settings, refused with the flag's problem when no atlas can be planned with them.
    fn settings(&self) -> Result<manylight_render::ShadowSettings> {
        let s = manylight_render::ShadowSettings {
            enabled: true,
            atlas_size: self.shadow_atlas,
            max_face_size: self.shadow_max_face,
            min_face_size: self.shadow_min_face,
            resolution_scale: self.shadow_resolution_scale,
            cascade_size: self.shadow_cascade_size,
            cache_maps: self.shadow_cache_maps,
            max_redrawn_maps: self.shadow_max_redrawn_maps.0,
            filter: self.shadow_filter,
        };
        s.check_values()
            .map_err(|e| anyhow::anyhow!("--{}", e.replace("shadows.", "shadow-").replace('_', "-")))?;
        Ok(s)
    }
}

/// What `render_scene` adds beyond the scene: post stages on the camera and the debug view.
#[derive(Clone, Copy, Debug, Default)]
struct Extras {
    bloom: Option<manylight_app::Bloom>,
    motion_blur: Option<manylight_app::MotionBlur>,
    debug: manylight_app::DebugView,
    /// Every light casts a shadow.
    shadows: bool,
}

/// Camera turn per frame under `--motion-blur` (about 20 px of motion at 1280 px wide).
const MOTION_BLUR_TURN: f32 = 0.015;

/// Light-assignment options of the tiled and clustered pipelines.
#[derive(clap::Args, Clone, Debug)]
struct ClusterArgs {
    /// Sphere–cluster test: aabb, planes or both (both must accept; the tightest).
    #[arg(long, default_value = "both", value_parser = parse_cull)]
    cull: CullTest,
    /// Depth slicing: linear or exponential.
    #[arg(long, default_value = "exponential", value_parser = parse_slicing)]
    z_slicing: ZSlicing,
    /// Grid size XxYxZ (default: tiles of about 16 px, 24 slices; Forward+ uses Z = 1).
    #[arg(long, value_parser = parse_grid)]
    grid: Option<UVec3>,
    /// Keep at most N lights per cluster (dropped pairs are counted in the stats).
    #[arg(long)]
    cluster_cap: Option<u32>,
    /// Skip the depth pre-pass of clustered forward (Forward+ always runs it).
    #[arg(long)]
    no_depth_prepass: bool,
    /// Workgroup size of the cluster-build compute shader.
    #[arg(long, default_value_t = 64)]
    workgroup_size: u32,
    /// Tiles per coarse-tile edge of the cluster build's first level (0: no coarse level,
    /// every tile tests every light).
    #[arg(long, default_value_t = manylight_render::DEFAULT_COARSE_TILES)]
    coarse_tiles: u32,
    /// Per-cluster depth bounds (cut clusters to their pixels' depth range; applies after a
    /// depth pre-pass or a G-buffer, without blended materials): on or off. Default: on, off for
    /// `sphere-shell`, whose lights hug its only surface, so the bounds cut nothing there and
    /// cost their pass (docs/benchmarks.md).
    #[arg(long, value_parser = parse_on_off)]
    depth_bounds: Option<bool>,
    /// Refined light lists (each 4 × 4-pixel block keeps the lights of its cluster lists that
    /// reach its pixels' surface box; applies where depth bounds can, not to tiled deferred):
    /// on or off (default on; docs/benchmarks.md, "Refined light lists").
    #[arg(long, value_parser = parse_on_off)]
    refined_lists: Option<bool>,
    /// G-buffer layout of the deferred pipelines (clustered-deferred, tiled-deferred,
    /// light-volumes): full, packed or compact.
    #[arg(long, default_value = "full", value_parser = parse_gbuffer)]
    gbuffer: GBufferLayout,
    /// Normal codec of the packed and compact G-buffers: xyz (packed only), spherical,
    /// octa16 or octa8. The full G-buffer stores normals unencoded.
    #[arg(long, default_value = "octa16", value_parser = parse_normal_codec)]
    normal_codec: NormalCodec,
    /// Debug view: none, albedo, normal, metallic, roughness, emissive, occlusion, depth,
    /// light-count, slice-x, slice-y, slice-z, overflow, shadow-atlas or shadow-lod (replaces
    /// tone mapping).
    #[arg(long, default_value = "none", value_parser = parse_debug_view)]
    debug_view: DebugViewMode,
    /// Anisotropic filtering of every texture: at most N samples per pixel footprint, 1 to 16
    /// (1 = off). Costly on lavapipe (docs/benchmarks.md).
    #[arg(long, default_value_t = manylight_core::material::MAX_ANISOTROPY,
          value_parser = clap::value_parser!(u16).range(1..=16))]
    anisotropy: u16,
}

impl ClusterArgs {
    /// `spec` loaded (as [`load_scene`] does) with these options' texture filtering.
    fn load(&self, spec: &str) -> Result<manylight_scene::Scene> {
        let mut scene = load_scene(spec, &LoadOptions::default())?;
        scene.set_anisotropy(self.anisotropy);
        Ok(scene)
    }

    /// The cluster settings for scene `spec` (`--depth-bounds` defaults per scene).
    fn settings(&self, spec: &str) -> ClusterSettings {
        ClusterSettings {
            grid: GridConfig { dims: self.grid, slicing: self.z_slicing, ..GridConfig::default() },
            cull: self.cull,
            cap: self.cluster_cap,
            depth_prepass: !self.no_depth_prepass,
            workgroup_size: self.workgroup_size,
            coarse_tiles: self.coarse_tiles,
            depth_bounds: self.depth_bounds.unwrap_or(spec != "sphere-shell"),
            refined_lists: self.refined_lists.unwrap_or(true),
        }
    }
}

/// Renders `scene` headless through the plugin and returns the last frame and its stats.
fn render_scene(
    scene: Scene,
    size: UVec2,
    frames: u32,
    lights: usize,
    seed: u64,
    settings: RenderSettings,
    extras: Extras,
) -> Result<(image::RgbaImage, FrameStats)> {
    use bevy_ecs::prelude::{Entity, Query, With};
    use manylight_app::{Camera3d, Transform};
    let aspect = size.x as f32 / size.y as f32;
    let bounds = scene.bounds();
    let frame = render_headless(size, frames, move |app| {
        app.insert_resource(settings).insert_resource(extras.debug).add_systems(
            Startup,
            move |mut commands: Commands| {
                spawn_scene(&mut commands, &scene, true, aspect);
                // The count was checked before the app was built; memory taken since then fails
                // the run with the error instead of a frame without the lights.
                if let Err(e) = spawn_light_rig(&mut commands, lights, bounds, seed) {
                    commands.insert_resource(manylight_app::RenderFailure(Some(format!("--lights: {e}"))));
                }
            },
        );
        app.add_systems(
            bevy_app::PostStartup,
            move |mut commands: Commands, cameras: Query<Entity, With<Camera3d>>| {
                for camera in &cameras {
                    let mut camera = commands.entity(camera);
                    if let Some(bloom) = extras.bloom {
                        camera.insert(bloom);
                    }
                    if let Some(motion_blur) = extras.motion_blur {
                        camera.insert(motion_blur);
                    }
                }
            },
        );
        if extras.shadows {
            app.add_systems(bevy_app::PostStartup, |world: &mut bevy_ecs::world::World| {
                manylight_app::scene::set_shadows(world, true)
            });
        }
        if extras.motion_blur.is_some() {
            app.add_systems(bevy_app::Update, |mut cameras: Query<&mut Transform, With<Camera3d>>| {
                for mut t in &mut cameras {
                    t.rotation = glam::Quat::from_rotation_y(MOTION_BLUR_TURN) * t.rotation;
                }
            });
        }
    })
    .map_err(anyhow::Error::msg)?;
    Ok((frame.image, frame.stats))
}

/// Refuses `count` lights — all the lights a command would create, named by `flags` — past the
/// light limit of the adapter the command renders with, or past the memory available, before
/// any light is created.
fn check_lights(count: usize, flags: &str) -> Result<()> {
    use manylight_core::light_count::{APP_BYTES_PER_LIGHT, check_light_count};
    let limit = manylight_render::context::adapter_light_limit()?;
    check_light_count(count, limit, APP_BYTES_PER_LIGHT).with_context(|| flags.to_string())
}

/// Reorders or clears the scene's cameras so the chosen one comes first.
fn select_camera(scene: &mut Scene, choice: &str) -> Result<()> {
    match choice {
        "scene" => {}
        "fit" => scene.cameras.clear(),
        index => {
            let i: usize = index
                .parse()
                .with_context(|| format!("--camera `{index}`: expected scene, fit or a number"))?;
            if i >= scene.cameras.len() {
                bail!("--camera {i}: the scene has {} cameras", scene.cameras.len());
            }
            scene.cameras.swap(0, i);
        }
    }
    Ok(())
}

fn stats_json(stats: &FrameStats) -> serde_json::Value {
    // Plain data with string keys: it serialises to a value whatever it holds.
    serde_json::to_value(stats.document()).unwrap_or(serde_json::Value::Null)
}

/// Times `snapshot`'s shading passes against the oracle's (the same frame shaded from exact
/// per-pixel lists): 3 frames of each, interleaved after a warm-up, medians. Prints and returns
/// (pipeline ms, oracle ms).
fn measure_oracle(snapshot: manylight_render::FrameSnapshot, pipeline: PipelineKind) -> Result<(f64, f64)> {
    let mut renderer = manylight_app::render_world::HeadlessRenderer::new()?;
    let (oracle, _) = direct::oracle_snapshot(&mut renderer, snapshot.clone())?;
    let names = [pipeline.name().to_string(), "oracle".to_string()];
    let snapshots = [snapshot, oracle];
    let (_, timed) = direct::interleaved(&names, 3, "frames", |i, _| snapshots[i].clone())?;
    let shading = |frames: &[direct::TimedFrame], what: &str| -> Result<f64> {
        let ms = frames.iter().map(|f| bench::shading_ms(&f.report)).collect::<Option<Vec<f64>>>();
        Ok(bench::median(&ms.with_context(|| format!("no GPU timings for {what}'s shading"))?))
    };
    let (ours, floor) = (shading(&timed[0], pipeline.name())?, shading(&timed[1], "the oracle")?);
    println!(
        "oracle: {} shades in {ours:.1} ms GPU, the oracle (exact per-pixel lists) in {floor:.1} ms: {:.2}x the floor (medians of 3)",
        pipeline.name(),
        ours / floor
    );
    Ok((ours, floor))
}

/// Measures `snapshot`'s shadows against exact visibility through `scene`'s triangles and
/// prints the result.
fn measure_shadow_accuracy(
    scene: &Scene,
    snapshot: manylight_render::FrameSnapshot,
) -> Result<shadow_error::ShadowAccuracy> {
    let mut renderer = manylight_app::render_world::HeadlessRenderer::new()?;
    let occluders = shadow_error::occluders(scene);
    let a = shadow_error::measure_shadows(&mut renderer, snapshot, &occluders)?;
    println!(
        "shadow oracle: visibility error {:.4} (false shadow {:.4}, light leak {:.4}) over {} \
         contributing light-pixel pairs ({} blocked, {} tested on the wrong side); FLIP against \
         the shadow reference: mean {:.4}, p99 {:.4}; the oracle cast {} rays in {:.0} ms",
        a.visibility_error,
        a.false_shadow,
        a.light_leak,
        a.contributing_pairs,
        a.blocked_pairs,
        a.wrong_pairs,
        a.flip.mean,
        a.flip.p99,
        a.rays,
        a.ray_cast_ms
    );
    if !scene.directional_lights.is_empty() {
        println!(
            "shadow oracle: the {} directional light(s) are not measured (the reference keeps their cascades)",
            scene.directional_lights.len()
        );
    }
    Ok(a)
}

fn render(args: RenderArgs) -> Result<()> {
    let mut scene = args.clusters.load(&args.scene)?;
    select_camera(&mut scene, &args.camera)?;
    let lit = add_render_lights(&mut scene, &args)?;
    let ambient = args.ambient.unwrap_or(if lit.unlit { 0.2 } else { RenderSettings::default().ambient });
    let shadow_settings = args.shadow.settings()?;
    let measured = measured_snapshot(&args, &scene, lit.rig, shadow_settings)?;
    let culling = match &measured {
        Some(snap) if args.culling_efficiency => Some(measure_culling_efficiency(snap.clone())?),
        _ => None,
    };
    let shadow_accuracy = match &measured {
        Some(snap) if args.shadow_oracle => {
            let a = measure_shadow_accuracy(&scene, snap.clone())?;
            if let Some(path) = &args.shadow_reference {
                save_png(&a.reference, path).map_err(anyhow::Error::msg)?;
                println!("wrote the shadow reference to {}", path.display());
            }
            Some(a)
        }
        _ => None,
    };
    let oracle = match measured {
        Some(snap) if args.oracle => Some(measure_oracle(snap, args.pipeline)?),
        _ => None,
    };
    let settings = app_settings(&args, ambient, shadow_settings);
    let frames = if args.post.motion_blur { args.frames.max(2) } else { args.frames };
    let (image, stats) =
        render_scene(scene, args.size, frames, lit.rig, args.seed, settings, render_extras(&args))?;
    save_png(&image, &args.out).map_err(anyhow::Error::msg)?;
    if let Some(path) = &args.stats_json {
        let json = render_stats_json(&stats, oracle, shadow_accuracy.as_ref(), culling);
        let text = serde_json::to_string_pretty(&json)?;
        std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(r) = &stats.last {
        print_written(&args.out, r);
    }
    Ok(())
}

/// What `render` lights its scene with beyond the scene's own lights.
struct RenderLights {
    /// Animated rig lights the app spawns (`--lights`; none for the sphere-shell preset).
    rig: usize,
    /// The scene is unlit by itself: it brings no lights of its own (for the sphere-shell
    /// preset: its lattice is empty), so ambient light and studio lights default higher.
    unlit: bool,
}

/// Adds the sphere-shell preset's lattice and the studio lights to `scene`, after checking
/// every light the command creates against the adapter's light limit and the memory.
fn add_render_lights(scene: &mut Scene, args: &RenderArgs) -> Result<RenderLights> {
    // The sphere-shell preset is lit by its own lattice (`--lights`, default 100 000 of range
    // 0.3 just inside the radius-50 sphere), not by the animated rig.
    let shell = args.scene == "sphere-shell";
    let shell_lights = if shell { args.lights.unwrap_or(100_000) } else { 0 };
    // A scene lit only by directional lights is lit: studio lights are for scenes with none.
    let unlit = if shell {
        shell_lights == 0
    } else {
        scene.lights.is_empty() && scene.directional_lights.is_empty()
    };
    let lights = if shell { 0 } else { args.lights.unwrap_or(0) };
    let studio = args.studio_lights.unwrap_or(if unlit && args.lights.is_none() { 32 } else { 0 });
    let total = [scene.lights.len(), shell_lights, lights, studio].into_iter().fold(0, usize::saturating_add);
    check_lights(total, "--lights and --studio-lights (with the scene's own lights)")?;
    if shell {
        scene.lights = manylight_scene::sphere_shell_lights(
            shell_lights,
            manylight_scene::SHELL_RADIUS,
            manylight_scene::SHELL_LIGHT_RANGE,
            args.seed,
        )?;
    }
    let studio = manylight_scene::studio_lights(studio, scene.bounds())?;
    scene.lights.extend(studio);
    Ok(RenderLights { rig: lights, unlit })
}

/// The measured frame of `--culling-efficiency`, `--oracle` and `--shadow-oracle` (`None`
/// without them): the last frame's animation time with `rig_lights` rig lights, rendered
/// straight from the scene (no app).
fn measured_snapshot(
    args: &RenderArgs,
    scene: &Scene,
    rig_lights: usize,
    shadows: manylight_render::ShadowSettings,
) -> Result<Option<manylight_render::FrameSnapshot>> {
    if !(args.culling_efficiency || args.oracle || args.shadow_oracle) {
        return Ok(None);
    }
    let rig = manylight_scene::light_rig(rig_lights, scene.bounds(), args.seed)?;
    let t = args.frames.max(1).saturating_sub(1) as f32 / 60.0;
    let settings = manylight_render::FrameSettings {
        render: manylight_render::RenderSettings {
            pipeline: args.pipeline,
            shading: args.shading,
            clusters: args.clusters.settings(&args.scene),
            gbuffer: args.clusters.gbuffer,
            normal_codec: args.clusters.normal_codec,
            shadows,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut snapshot = direct::snapshot(scene, &rig, t, args.size, settings, 0);
    if args.shadows {
        direct::cast_every_shadow(&mut snapshot);
    }
    Ok(Some(snapshot))
}

/// Measures the culling efficiency of `snapshot`'s lists, and of the lists depth bounds and
/// z-binning would make (measured, not built), prints them and returns the lists'.
fn measure_culling_efficiency(
    snapshot: manylight_render::FrameSnapshot,
) -> Result<manylight_core::efficiency::CullingEfficiency> {
    let mut renderer = manylight_app::render_world::HeadlessRenderer::new()?;
    let (_, culling) = direct::measure_culling(&mut renderer, snapshot)?;
    let eff = culling.lists;
    println!(
        "culling efficiency: {} light-pixel pairs evaluated, {} contributing: {:.3}x \
         ({} sampled pixels, {} contributing pairs missing from the lists)",
        eff.evaluated_pairs,
        eff.contributing_pairs,
        eff.ratio(),
        eff.sampled_pixels,
        eff.missed_pairs
    );
    let bounded = culling.depth_bounded;
    println!(
        "with per-cluster depth bounds (measured on these lists, not built): {} pairs \
         evaluated: {:.3}x ({} contributing pairs missing)",
        bounded.evaluated_pairs,
        bounded.ratio(),
        bounded.missed_pairs
    );
    if let Some(z) = culling.zbinned {
        println!(
            "with z-binning of the tile lists ({} bins; measured, not built): {} pairs \
             evaluated: {:.3}x ({} contributing pairs missing)",
            direct::ZBINS,
            z.evaluated_pairs,
            z.ratio(),
            z.missed_pairs
        );
    }
    Ok(eff)
}

/// The app's settings for `render`, from the command line.
fn app_settings(
    args: &RenderArgs,
    ambient: f32,
    shadows: manylight_render::ShadowSettings,
) -> RenderSettings {
    RenderSettings {
        pipeline: args.pipeline,
        shading: args.shading,
        exposure: args.ev100.map_or(args.exposure, |ev100| manylight_app::Exposure { ev100 }.multiplier()),
        ambient,
        clusters: args.clusters.settings(&args.scene),
        gbuffer: args.clusters.gbuffer,
        normal_codec: args.clusters.normal_codec,
        shadows,
        ..RenderSettings::default()
    }
}

/// The post stages, debug view and shadows `render` adds to the scene.
fn render_extras(args: &RenderArgs) -> Extras {
    Extras {
        bloom: args.post.bloom.then(|| manylight_app::Bloom {
            chain: args.post.bloom_chain,
            ..manylight_app::Bloom::default()
        }),
        motion_blur: args.post.motion_blur.then(manylight_app::MotionBlur::default),
        debug: manylight_app::DebugView::new(args.clusters.debug_view),
        shadows: args.shadows,
    }
}

/// `--stats-json`'s document: the last frame's statistics ([`stats_json`]) and the
/// measurements `render` made of it.
fn render_stats_json(
    stats: &FrameStats,
    oracle: Option<(f64, f64)>,
    shadow_accuracy: Option<&shadow_error::ShadowAccuracy>,
    culling: Option<manylight_core::efficiency::CullingEfficiency>,
) -> serde_json::Value {
    let mut json = stats_json(stats);
    if let Some((ours, floor)) = oracle {
        json["oracle"] = serde_json::json!({
            "shading_ms": ours,
            "oracle_shading_ms": floor,
            "shading_vs_oracle": ours / floor,
        });
    }
    if let Some(a) = shadow_accuracy {
        json["shadow_oracle"] = serde_json::json!({
            "contributing_pairs": a.contributing_pairs,
            "blocked_pairs": a.blocked_pairs,
            "wrong_pairs": a.wrong_pairs,
            "visibility_error": a.visibility_error,
            "false_shadow": a.false_shadow,
            "light_leak": a.light_leak,
            "flip_vs_shadow_reference": a.flip.mean,
            "flip_vs_shadow_reference_p99": a.flip.p99,
            "rays": a.rays,
            "ray_cast_ms": a.ray_cast_ms,
        });
    }
    if let Some(e) = culling {
        json["culling_efficiency"] = serde_json::json!({
            "pixels": e.pixels,
            "evaluated_pairs": e.evaluated_pairs,
            "contributing_pairs": e.contributing_pairs,
            "ratio": e.ratio(),
            "sampled_pixels": e.sampled_pixels,
            "missed_pairs": e.missed_pairs,
        });
    }
    json
}

/// Prints what `render` wrote to `out`: the last frame's size, lights, instances and passes.
fn print_written(out: &std::path::Path, r: &manylight_render::FrameReport) {
    let passes: Vec<String> = r
        .passes
        .iter()
        .map(|p| match p.gpu_ms {
            Some(g) => format!("{} {:.2} ms", p.name, g),
            None => format!("{} (cpu {:.2} ms)", p.name, p.cpu_ms),
        })
        .collect();
    println!(
        "wrote {} ({}x{}, {} lights, {} instances): {}",
        out.display(),
        r.width,
        r.height,
        r.light_count,
        r.instance_count,
        passes.join(", ")
    );
}

fn check(path: PathBuf) -> Result<()> {
    let spec = path.to_string_lossy().to_string();
    let scene = manylight_scene::load_gltf(&path, &LoadOptions::default())?;
    let summary = format!(
        "{}: {} meshes, {} materials, {} instances, {} lights, {} cameras",
        path.display(),
        scene.meshes.len(),
        scene.materials.len(),
        scene.instances.len(),
        scene.lights.len(),
        scene.cameras.len()
    );
    render_scene(scene, UVec2::new(64, 64), 1, 0, 1, RenderSettings::default(), Extras::default())
        .with_context(|| format!("`{spec}` loaded but did not render"))?;
    println!("ok: {summary}");
    Ok(())
}

/// The scene's name in tables and figure titles: the preset's name, or the file's stem.
fn scene_name(spec: &str) -> String {
    match spec {
        "default" | "sphere-shell" => spec.to_string(),
        path => std::path::Path::new(path)
            .file_stem()
            .map_or_else(|| path.to_string(), |s| s.to_string_lossy().into_owned()),
    }
}

/// Writes `csv` as `<dir>/<name>.csv` and its figures beside it; prints what it wrote.
fn write_plots(dir: &std::path::Path, name: &str, csv: &str) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let path = dir.join(format!("{name}.csv"));
    std::fs::write(&path, csv).with_context(|| format!("cannot write {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    for figure in plot::figures_named(csv, dir, Some(name))? {
        eprintln!("wrote {}", figure.display());
    }
    Ok(())
}

/// The settings the measuring subcommands (`report`, `rangeless-lights`, `post`, `views`)
/// start from: the defaults with the command line's cluster settings for `scene`.
fn measure_base(clusters: &ClusterArgs, scene: &str) -> manylight_render::FrameSettings {
    manylight_render::FrameSettings {
        render: manylight_render::RenderSettings { clusters: clusters.settings(scene), ..Default::default() },
        ..Default::default()
    }
}

fn rangeless_lights_cmd(args: ReportArgs) -> Result<()> {
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

fn report_cmd(args: ReportArgs) -> Result<()> {
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

fn post_cmd(args: ReportArgs) -> Result<()> {
    let scene = args.clusters.load(&args.scene)?;
    check_lights(scene.lights.len().saturating_add(args.lights), "--lights")?;
    let base = measure_base(&args.clusters, &args.scene);
    let name = scene_name(&args.scene);
    let report = post::run(&scene, &name, args.lights, args.size, args.frames.max(1), base)?;
    print!("{}", report.markdown);
    if let Some(dir) = &args.plot {
        write_plots(dir, "post", &report.csv)?;
    }
    Ok(())
}

fn views_cmd(args: ViewsArgs) -> Result<()> {
    let scene = args.clusters.load(&args.scene)?;
    check_lights(scene.lights.len().saturating_add(args.lights), "--lights")?;
    let base = measure_base(&args.clusters, &args.scene);
    let name = scene_name(&args.scene);
    print!("{}", views::run(&scene, &name, args.lights, args.size, args.frames.max(1), base)?);
    Ok(())
}

fn plot_cmd(csv: PathBuf, out: PathBuf) -> Result<()> {
    let text = std::fs::read_to_string(&csv).with_context(|| format!("cannot read {}", csv.display()))?;
    for figure in plot::figures(&text, &out).with_context(|| format!("{}", csv.display()))? {
        eprintln!("wrote {}", figure.display());
    }
    Ok(())
}

fn codec_accuracy_cmd(samples: usize) -> Result<()> {
    let mut progress =
        progress::Progress::new(manylight_core::codec::NormalCodec::ALL.len() as u64 + 2, "codecs");
    let table = codec_accuracy::table(samples, |label| progress.step(|| label.to_string()));
    progress.finish();
    print!("{table}");
    Ok(())
}

fn bench_cmd(args: BenchArgs) -> Result<()> {
    let scene = args.clusters.load(&args.scene)?;
    let most = args.lights.iter().copied().max().unwrap_or(0);
    check_lights(scene.lights.len().saturating_add(most), "--lights")?;
    let sweep = bench::Sweep {
        pipelines: args.pipelines,
        lights: args.lights,
        size: args.size,
        warmup: args.warmup,
        frames: args.frames.max(1),
        naive_max_lights: args.naive_max_lights,
        culling_efficiency: args.culling_efficiency,
        oracle: args.oracle,
        shell_lattice: args.scene == "sphere-shell",
        gbuffers: args.gbuffers,
        shadows: args.shadows,
        shadow_oracle: args.shadow_oracle,
        settings: manylight_render::FrameSettings {
            render: manylight_render::RenderSettings {
                clusters: args.clusters.settings(&args.scene),
                gbuffer: args.clusters.gbuffer,
                normal_codec: args.clusters.normal_codec,
                shading: args.shading,
                shadows: args.shadow.settings()?,
                ..Default::default()
            },
            ..Default::default()
        },
    };
    let csv = bench::run(&scene, &scene_name(&args.scene), &sweep)?;
    if let Some(parent) = args.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
    }
    std::fs::write(&args.out, &csv).with_context(|| format!("cannot write {}", args.out.display()))?;
    print!("{csv}");
    eprintln!("wrote {}", args.out.display());
    if let Some(dir) = &args.plot {
        for figure in plot::figures(&csv, dir)? {
            eprintln!("wrote {}", figure.display());
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| "warn,manylight=info".into()),
        )
        .with_writer(std::io::stderr)
        .init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render(args),
        Command::Check { path } => check(path),
        Command::Bench(args) => bench_cmd(args),
        Command::Report(args) => report_cmd(args),
        Command::RangelessLights(args) => rangeless_lights_cmd(args),
        Command::Post(args) => post_cmd(args),
        Command::Views(args) => views_cmd(args),
        Command::Plot { csv, out } => plot_cmd(csv, out),
        Command::Soak(args) => soak::run(args),
        Command::DepthPrecision { samples } => {
            print!("{}", depth_precision::tables(samples.max(1)));
            Ok(())
        }
        Command::CodecAccuracy { samples } => codec_accuracy_cmd(samples.max(1)),
        Command::CullingTests { lights, seed } => manylight_core::light_count::check_app_lights(lights)
            .map_err(anyhow::Error::from)
            .map(|()| print!("{}", culling_tests::table(lights, seed))),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
