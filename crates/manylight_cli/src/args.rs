//! What the `manylight` command line holds: the subcommands, their flags with defaults and
//! help text, and how the flag groups shared by several subcommands (cluster, shadow and post
//! options) become the renderer's settings.

use crate::{large_floor, soak};
use anyhow::Result;
use clap::{Parser, Subcommand};
use glam::{UVec2, UVec3};
use manylight_app::cli::{
    parse_ambient, parse_bloom_chain, parse_cull, parse_debug_view, parse_ev100, parse_exposure,
    parse_gbuffer, parse_grid, parse_normal_codec, parse_on_off, parse_pipeline, parse_redraw_budget,
    parse_shading, parse_size, parse_slicing,
};
use manylight_core::ShadingModel;
use manylight_core::cluster::{CullTest, GridConfig, ZSlicing};
use manylight_core::codec::NormalCodec;
use manylight_render::{BloomChain, ClusterSettings, DebugViewMode, GBufferLayout, PipelineKind};
use manylight_scene::{LoadOptions, load_scene};
use std::path::PathBuf;

#[derive(Parser)]
#[command(name = "manylight", version, about = "Many-light rendering with wgpu: render, check, bench")]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand)]
pub(crate) enum Command {
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
    /// FLIP between two PNGs of one size (mean, 95th and 99th percentile, max), e.g. a render
    /// against a glTF sample's screenshot; optionally writes the error map.
    Compare {
        /// The reference image.
        reference: PathBuf,
        /// The image compared with it.
        test: PathBuf,
        /// Write the FLIP error map here (PNG, magma colours).
        #[arg(long)]
        error_map: Option<PathBuf>,
    },
    /// How far split-sum image-based lighting is from a Monte-Carlo reference on a grid of
    /// spheres, for prefilter samples, cube sizes and lookup-table sizes, with each setting's
    /// prefilter time and per-frame cost, as markdown tables.
    EnvironmentAccuracy(EnvironmentAccuracyArgs),
    /// What shadow rays cost: building the scene's two-level BVH (time, bytes, depth) and
    /// tracing each pixel's rays to the lights that reach its surface, on the GPU, on the
    /// traversal's CPU twin and on the CPU oracle, as markdown tables.
    ShadowRays(ShadowRaysArgs),
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
pub(crate) struct ShadowRaysArgs {
    /// The scene: `default`, `sphere-shell` or a .gltf/.glb path.
    #[arg(long, default_value = "default")]
    pub(crate) scene: String,
    /// Lights of the animated rig (as `bench --lights`), where they are at time 0.
    #[arg(long, default_value_t = 100_000)]
    pub(crate) lights: usize,
    /// Pixels, WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub(crate) size: UVec2,
    /// Rays a pixel, one row each (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "1,2,4,8")]
    pub(crate) rays_per_pixel: Vec<u32>,
    /// Seed of the light rig.
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Timed GPU traces and instance-level builds per row (medians).
    #[arg(long, default_value_t = 3)]
    pub(crate) repeats: u32,
}

#[derive(clap::Args)]
pub(crate) struct EnvironmentAccuracyArgs {
    /// The panorama (.hdr or .exr) that lights the spheres.
    #[arg(long, default_value = "assets/environments/studio_small_03.hdr")]
    pub(crate) environment: PathBuf,
    /// Image size, WxH.
    #[arg(long, default_value = "320x128", value_parser = parse_size)]
    pub(crate) size: UVec2,
    /// Samples per pixel of each of the two Monte-Carlo references (each sample draws a GGX,
    /// a cosine-distributed and an environment direction).
    #[arg(long, default_value_t = 4096)]
    pub(crate) reference_samples: u32,
    /// Timed frames per setting, with and without the environment (medians).
    #[arg(long, default_value_t = 9)]
    pub(crate) frames: u32,
    /// Also write the results as CSV here.
    #[arg(long)]
    pub(crate) csv: Option<PathBuf>,
    /// Draw error against prefilter time (PNG) here.
    #[arg(long)]
    pub(crate) figure: Option<PathBuf>,
}

#[derive(clap::Args)]
pub(crate) struct ReportArgs {
    /// `default`, `sphere-shell` or a .gltf/.glb path.
    #[arg(long, default_value = "default")]
    pub(crate) scene: String,
    /// Rig lights.
    #[arg(long, default_value_t = 1024)]
    pub(crate) lights: usize,
    /// Image size, WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub(crate) size: UVec2,
    /// Timed frames per configuration (after one warm-up).
    #[arg(long, default_value_t = 2)]
    pub(crate) frames: u32,
    #[command(flatten)]
    pub(crate) clusters: ClusterArgs,
    /// Also write the results as CSV and PNG figures into this folder.
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
    /// The shadow section instead (`report`): shadow settings — none, atlas sizes, resolution
    /// policies, redraw budgets with moving lights, caching with still ones — every light
    /// casting, each with its frame time, visibility error and FLIP against the shadow
    /// reference (`report_shadows.csv` and its figures with `--plot`).
    #[arg(long)]
    pub(crate) shadows: bool,
    /// The very-large-surfaces section instead (`report`): a floor quad with corners at ±extent
    /// under four point lights, flat and tilted, drawn by every pipeline, G-buffer layout and
    /// normal codec at `--size` against the same floor tessellated into rings that grow with the
    /// distance from the camera (naive forward), and those rings against the floor shaded
    /// analytically on the CPU: FLIP mean and p99, worst 8-bit channel and non-finite pixels,
    /// one frame each, as a markdown table. Draws its own floor: no scene, rig lights or timing.
    #[arg(long, conflicts_with_all = ["shadows", "plot", "scene", "lights", "frames"])]
    pub(crate) large_floor: bool,
    /// Half-sizes of the floor `--large-floor` measures (`report`).
    #[arg(long, value_delimiter = ',', default_value = "10,1e4,1e7", requires = "large_floor",
          value_parser = large_floor::parse_extent)]
    pub(crate) floor_extents: Vec<f64>,
    /// Far plane of `--large-floor`'s camera, or `inf` for none (`report`).
    #[arg(long, default_value = "1e8", requires = "large_floor", value_parser = large_floor::parse_far)]
    pub(crate) floor_far: f32,
}

#[derive(clap::Args)]
pub(crate) struct ViewsArgs {
    /// `default`, `sphere-shell` or a .gltf/.glb path.
    #[arg(long, default_value = "default")]
    pub(crate) scene: String,
    /// Rig lights.
    #[arg(long, default_value_t = 1024)]
    pub(crate) lights: usize,
    /// Size of the whole target, WxH (the views split it).
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub(crate) size: UVec2,
    /// Timed frames per view count (after one warm-up).
    #[arg(long, default_value_t = 5)]
    pub(crate) frames: u32,
    #[command(flatten)]
    pub(crate) clusters: ClusterArgs,
}

// One field a flag of `manylight bench` (over 15): clap derives the command line from it.
#[derive(clap::Args)]
pub(crate) struct BenchArgs {
    /// `default`, `sphere-shell` or a .gltf/.glb path.
    #[arg(long, default_value = "default")]
    pub(crate) scene: String,
    /// Comma-separated pipelines.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "naive,forward-plus,clustered-forward,clustered-deferred",
        value_parser = parse_pipeline
    )]
    pub(crate) pipelines: Vec<PipelineKind>,
    /// Comma-separated rig light counts.
    #[arg(long, value_delimiter = ',', default_value = "16,64,256,1024,4096,16384")]
    pub(crate) lights: Vec<usize>,
    /// Image size, WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub(crate) size: UVec2,
    /// Frames measured per configuration (the median is reported).
    #[arg(long, default_value_t = 3)]
    pub(crate) frames: u32,
    /// Frames rendered first and not measured (pipeline creation, uploads).
    #[arg(long, default_value_t = 1)]
    pub(crate) warmup: u32,
    /// Skip naive forward above this many lights (it costs seconds per frame on a CPU).
    #[arg(long, default_value_t = 1024)]
    pub(crate) naive_max_lights: usize,
    /// Also measure each tiled/clustered configuration's culling efficiency.
    #[arg(long)]
    pub(crate) culling_efficiency: bool,
    /// Also render each light count's frames with exact per-pixel light lists built on the CPU
    /// from the read-back depth (not timed): the floor of culling. Every row gets its shading
    /// time against the oracle's (`shading_vs_oracle`).
    #[arg(long)]
    pub(crate) oracle: bool,
    /// G-buffer layouts swept for the deferred pipelines (clustered-deferred, tiled-deferred,
    /// light-volumes).
    #[arg(long, value_delimiter = ',', default_value = "full,compact", value_parser = parse_gbuffer)]
    pub(crate) gbuffers: Vec<GBufferLayout>,
    /// Comma-separated shadow settings swept: `off` (no light casts), `on` or `maps` (every
    /// light of the scene and the rig casts into the shadow atlas), `rays` (every light casts,
    /// found with rays through the scene's BVH).
    #[arg(long, value_delimiter = ',', default_value = "off", value_parser = manylight_app::cli::parse_shadows)]
    pub(crate) shadows: Vec<manylight_app::cli::ShadowChoice>,
    /// Also measure each pipeline row's last frame against exact visibility: the CSV columns
    /// `visibility_error` (mean |shadow test - exact| over the light-pixel pairs the light
    /// reaches), `flip_vs_shadow_reference` (FLIP mean against naive forward with exact
    /// visibility), `light_error` (sum of |HDR luminance - the reference's| over the sum of the
    /// unshadowed frame's) and `flicker` (mean |next still frame - frame| over the mean, HDR
    /// luminance). Not timed.
    #[arg(long)]
    pub(crate) shadow_oracle: bool,
    #[command(flatten)]
    pub(crate) shadow: ShadowArgs,
    #[command(flatten)]
    pub(crate) clusters: ClusterArgs,
    /// Shading model for materials without their own: pbr (default), lambert, blinn-phong or toon.
    #[arg(long, default_value = "pbr", value_parser = parse_shading)]
    pub(crate) shading: ShadingModel,
    /// CSV output.
    #[arg(long)]
    pub(crate) out: PathBuf,
    /// Also draw PNG figures of the CSV into this folder.
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
}

// One field a flag of `manylight render` (over 15; the cluster and shadow flags are groups of
// their own): clap derives the command line from it.
#[derive(clap::Args)]
pub(crate) struct RenderArgs {
    /// `default` (embedded hall), `sphere-shell`, or a path to a .gltf/.glb file.
    #[arg(long, default_value = "default")]
    pub(crate) scene: String,
    /// Pipeline: naive, forward-plus, clustered-forward, clustered-deferred, tiled-deferred or
    /// light-volumes.
    #[arg(long, default_value = "clustered-forward", value_parser = parse_pipeline)]
    pub(crate) pipeline: PipelineKind,
    #[command(flatten)]
    pub(crate) clusters: ClusterArgs,
    /// Shading model for materials without their own: pbr (default), lambert, blinn-phong or toon.
    #[arg(long, default_value = "pbr", value_parser = parse_shading)]
    pub(crate) shading: ShadingModel,
    /// Animated lights (inside the scene's bounds) added to the scene's own lights (default 0).
    /// For `sphere-shell`: the lights of its lattice instead (default 100 000).
    #[arg(long)]
    pub(crate) lights: Option<usize>,
    /// Static white lights on a dome around the scene, as a model viewer lights a model
    /// (default: 32 for a scene that brings no lights of its own and no `--lights`, so it is
    /// not black; 0 otherwise).
    #[arg(long)]
    pub(crate) studio_lights: Option<usize>,
    /// Image size, WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub(crate) size: UVec2,
    /// Frames to render (animation advances 1/60 s per frame); the last one is written.
    #[arg(long, default_value_t = 1)]
    pub(crate) frames: u32,
    /// Exposure multiplier before tone mapping.
    #[arg(long, default_value_t = 1.0, conflicts_with = "ev100", allow_hyphen_values = true, value_parser = parse_exposure)]
    pub(crate) exposure: f32,
    /// Photographic exposure value at ISO 100 instead of `--exposure` (multiplier
    /// 1 / (1.2 · 2^EV100)): about 15 for sunlight, 7 for a lamp-lit room, with lights in
    /// physical units.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_ev100)]
    pub(crate) ev100: Option<f32>,
    /// Constant ambient light, as a fraction of albedo (default: 0.03, or 0.2 for a scene
    /// that brings no lights of its own, so its shapes read).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_ambient)]
    pub(crate) ambient: Option<f32>,
    /// Seed of the light placement.
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Camera: `scene` (the file's first camera, else a fitted one), `fit` (frame the whole
    /// scene), the index of one of the file's cameras, `look-at:EX,EY,EZ:TX,TY,TZ:FOV_DEG` (a
    /// perspective camera at the eye looking at the target, +Y up, FOV_DEG degrees tall) or
    /// `ortho:EX,EY,EZ:TX,TY,TZ:HEIGHT` (orthographic, HEIGHT world units tall).
    #[arg(long, default_value = "scene")]
    pub(crate) camera: String,
    /// Shadows: `on` or `maps` makes every light of the scene and of `--lights` cast one into
    /// the shadow atlas (glTF has no shadow flag), `rays` finds every light's shadow with rays
    /// traced through the scene's BVH, `off` (default) none.
    #[arg(long, default_value = "off", value_parser = manylight_app::cli::parse_shadows)]
    pub(crate) shadows: manylight_app::cli::ShadowChoice,
    #[command(flatten)]
    pub(crate) shadow: ShadowArgs,
    /// Output PNG.
    #[arg(long)]
    pub(crate) out: PathBuf,
    /// Write the last frame's statistics as JSON here.
    #[arg(long)]
    pub(crate) stats_json: Option<PathBuf>,
    /// Measure the culling efficiency of the last frame: light-pixel pairs evaluated ÷ pairs
    /// with a non-zero contribution (CPU reference over the depth buffer read back).
    #[arg(long)]
    pub(crate) culling_efficiency: bool,
    /// Also time the shading of the last frame against the oracle's: the same frame shaded by
    /// clustered forward from exact per-pixel light lists built on the CPU (not timed) from
    /// its depth.
    #[arg(long)]
    pub(crate) oracle: bool,
    /// Also measure the last frame's shadows against exact visibility (a ray cast from every
    /// pixel's surface to each light that reaches it): prints the visibility error (mean
    /// |shadow test - exact| over those pairs), FLIP against the shadow reference (the
    /// oracle's lists without the blocked pairs: naive forward with exact visibility), the
    /// light error (sum of |HDR luminance - the reference's| over the sum of the unshadowed
    /// frame's) and the flicker (mean |next still frame - frame| over the mean, HDR luminance).
    #[arg(long)]
    pub(crate) shadow_oracle: bool,
    /// Where `--shadow-oracle` writes the shadow reference image (PNG).
    #[arg(long, requires = "shadow_oracle")]
    pub(crate) shadow_reference: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) post: PostArgs,
    #[command(flatten)]
    pub(crate) environment: EnvironmentArgs,
}

/// Image-based lighting of `render`: an HDR panorama that lights the scene and, by default,
/// shows behind it.
#[derive(clap::Args, Clone, Debug)]
pub(crate) struct EnvironmentArgs {
    /// An equirectangular HDR panorama (.hdr or .exr) that lights the scene (split-sum
    /// image-based lighting in every pipeline), e.g. assets/environments/studio_small_03.hdr.
    #[arg(long)]
    pub(crate) environment: Option<PathBuf>,
    /// Multiplies the panorama's radiance where it lights the scene.
    #[arg(long, default_value_t = 1.0, requires = "environment", value_parser = parse_environment_intensity)]
    pub(crate) environment_intensity: f32,
    /// `on` (default) draws the panorama behind the geometry, `off` keeps the clear colour.
    #[arg(long, default_value = "on", requires = "environment", value_parser = parse_on_off, action = clap::ArgAction::Set)]
    pub(crate) skybox: bool,
}

/// A finite, non-negative multiplier.
fn parse_environment_intensity(s: &str) -> Result<f32, String> {
    let value: f32 = s.parse().map_err(|e| format!("environment intensity `{s}`: {e}"))?;
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(format!("environment intensity `{s}`: a finite number of at least 0"))
    }
}

/// Opt-in post stages of `render`.
#[derive(clap::Args, Clone, Debug)]
pub(crate) struct PostArgs {
    /// Bloom on the camera.
    #[arg(long)]
    pub(crate) bloom: bool,
    /// Bloom chain: downsampled (halves the resolution per iteration) or full-resolution
    /// (separable 1×9/9×1 kernels, every iteration at full size).
    #[arg(long, default_value = "downsampled", value_parser = parse_bloom_chain)]
    pub(crate) bloom_chain: BloomChain,
    /// Camera-motion blur on the camera; the camera turns between frames so it shows (at least
    /// 2 frames are rendered).
    #[arg(long)]
    pub(crate) motion_blur: bool,
}

/// The shadow atlas and resolution policy (`manylight_render::ShadowSettings`).
#[derive(clap::Args, Clone, Debug)]
pub(crate) struct ShadowArgs {
    /// Largest edge of the shadow atlas in texels (a power of two).
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().atlas_size)]
    pub(crate) shadow_atlas: u32,
    /// Largest cube-face edge a point or spot light's shadow gets (a power of two).
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().max_face_size)]
    pub(crate) shadow_max_face: u32,
    /// Smallest cube-face edge (a power of two): below it a light goes without a shadow, counted.
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().min_face_size)]
    pub(crate) shadow_min_face: u32,
    /// Face texels asked per pixel of a light sphere's projected radius.
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().resolution_scale)]
    pub(crate) shadow_resolution_scale: f32,
    /// Edge of each cascade of a directional light (a power of two).
    #[arg(long, default_value_t = manylight_render::ShadowSettings::default().cascade_size)]
    pub(crate) shadow_cascade_size: u32,
    /// `on` (default): a light's map is kept from the frame before when neither the light nor
    /// the casters near it changed; `off`: every map is drawn every frame (the same image).
    #[arg(long, default_value = "on", value_parser = parse_on_off, action = clap::ArgAction::Set)]
    pub(crate) shadow_cache_maps: bool,
    /// Most point or spot light maps drawn again per frame when their light or casters changed,
    /// or `all`; the least important others keep an earlier frame's map, counted.
    #[arg(long, default_value = "256", value_parser = parse_redraw_budget)]
    pub(crate) shadow_max_redrawn_maps: manylight_app::cli::RedrawBudget,
    /// Filter of every shadow lookup: hardware2x2 (one bilinear comparison) or gaussian (four,
    /// a 3×3 tent).
    #[arg(long, default_value = "hardware2x2", value_parser = manylight_app::cli::parse_shadow_filter)]
    pub(crate) shadow_filter: manylight_render::ShadowFilteringMethod,
}

impl ShadowArgs {
    /// The settings, finding shadows by `method`, refused with the flag's problem when no
    /// atlas can be planned with them.
    pub(crate) fn settings(
        &self,
        method: manylight_render::ShadowMethod,
    ) -> Result<manylight_render::ShadowSettings> {
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
            method,
        };
        s.check_values()
            .map_err(|e| anyhow::anyhow!("--{}", e.replace("shadows.", "shadow-").replace('_', "-")))?;
        Ok(s)
    }
}

/// Light-assignment options of the tiled and clustered pipelines.
#[derive(clap::Args, Clone, Debug)]
pub(crate) struct ClusterArgs {
    /// Sphere–cluster test: aabb, planes or both (both must accept; the tightest).
    #[arg(long, default_value = "both", value_parser = parse_cull)]
    pub(crate) cull: CullTest,
    /// Depth slicing: linear or exponential.
    #[arg(long, default_value = "exponential", value_parser = parse_slicing)]
    pub(crate) z_slicing: ZSlicing,
    /// Grid size XxYxZ (default: tiles of about 16 px, 24 slices; Forward+ uses Z = 1).
    #[arg(long, value_parser = parse_grid)]
    pub(crate) grid: Option<UVec3>,
    /// Keep at most N lights per cluster (dropped pairs are counted in the stats).
    #[arg(long)]
    pub(crate) cluster_cap: Option<u32>,
    /// Skip the depth pre-pass of clustered forward (Forward+ always runs it).
    #[arg(long)]
    pub(crate) no_depth_prepass: bool,
    /// Workgroup size of the cluster-build compute shader.
    #[arg(long, default_value_t = 64)]
    pub(crate) workgroup_size: u32,
    /// Tiles per coarse-tile edge of the cluster build's first level (0: no coarse level,
    /// every tile tests every light).
    #[arg(long, default_value_t = manylight_render::DEFAULT_COARSE_TILES)]
    pub(crate) coarse_tiles: u32,
    /// Per-cluster depth bounds (cut clusters to their pixels' depth range; applies after a
    /// depth pre-pass or a G-buffer, without blended materials): on or off. Default: on, off for
    /// `sphere-shell`, whose lights hug its only surface, so the bounds cut nothing there and
    /// cost their pass (docs/benchmarks.md).
    #[arg(long, value_parser = parse_on_off)]
    pub(crate) depth_bounds: Option<bool>,
    /// Refined light lists (each 4 × 4-pixel block keeps the lights of its cluster lists that
    /// reach its pixels' surface box; applies where depth bounds can, not to tiled deferred):
    /// on or off (default on; docs/benchmarks.md, "Refined light lists").
    #[arg(long, value_parser = parse_on_off)]
    pub(crate) refined_lists: Option<bool>,
    /// G-buffer layout of the deferred pipelines (clustered-deferred, tiled-deferred,
    /// light-volumes): full, packed or compact.
    #[arg(long, default_value = "full", value_parser = parse_gbuffer)]
    pub(crate) gbuffer: GBufferLayout,
    /// Normal codec of the packed and compact G-buffers: xyz (packed only), spherical,
    /// octa16 or octa8. The full G-buffer stores normals unencoded.
    #[arg(long, default_value = "octa16", value_parser = parse_normal_codec)]
    pub(crate) normal_codec: NormalCodec,
    /// Debug view: none, albedo, normal, metallic, roughness, emissive, occlusion, depth,
    /// light-count, slice-x, slice-y, slice-z, overflow, shadow-atlas or shadow-lod (replaces
    /// tone mapping).
    #[arg(long, default_value = "none", value_parser = parse_debug_view)]
    pub(crate) debug_view: DebugViewMode,
    /// Anisotropic filtering of every texture: at most N samples per pixel footprint, 1 to 16
    /// (1 = off). Costly on lavapipe (docs/benchmarks.md).
    #[arg(long, default_value_t = manylight_core::material::MAX_ANISOTROPY,
          value_parser = clap::value_parser!(u16).range(1..=16))]
    pub(crate) anisotropy: u16,
}

impl ClusterArgs {
    /// `spec` loaded (as [`load_scene`] does) with these options' texture filtering.
    pub(crate) fn load(&self, spec: &str) -> Result<manylight_scene::Scene> {
        let mut scene = load_scene(spec, &LoadOptions::default())?;
        scene.set_anisotropy(self.anisotropy);
        Ok(scene)
    }

    /// The cluster settings for scene `spec` (`--depth-bounds` defaults per scene).
    pub(crate) fn settings(&self, spec: &str) -> ClusterSettings {
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
