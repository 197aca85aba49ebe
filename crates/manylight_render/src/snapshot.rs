//! The plain data one frame is rendered from. The app's extract system fills it from the ECS
//! world; the render side reads it and nothing else (it never reaches back into the ECS).

use glam::{Mat4, UVec2, Vec3};
use manylight_core::cluster::{CullTest, GridConfig};
use manylight_core::codec::NormalCodec;
use manylight_core::{MaterialData, MeshData, Projection, ShadingModel, SpotCone};
use std::sync::Arc;

pub use crate::settings::{BloomChain, BloomSettings, Exposure, MotionBlurSettings};

/// Which many-light pipeline renders the frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PipelineKind {
    /// Forward shading that evaluates every light for every fragment (the reference).
    NaiveForward,
    /// Tiled forward (Forward+): 2D screen tiles, one depth range (Z = 1), depth pre-pass.
    ForwardPlus,
    /// Clustered forward: screen tiles × depth slices, optional depth pre-pass (the default).
    #[default]
    ClusteredForward,
    /// Clustered deferred: a G-buffer pass, then one full-screen pass walks each pixel's
    /// cluster list.
    ClusteredDeferred,
    /// Tiled deferred in compute: a G-buffer pass, then one workgroup per screen tile finds its
    /// pixels' depth range and 2.5D depth mask, keeps the tile's lights that reach them in
    /// workgroup memory and shades its pixels from that shared list (one depth slice: the
    /// tile lists of the cluster build).
    TiledDeferred,
    /// Deferred light volumes: a G-buffer pass, then each light drawn as an instanced sphere
    /// proxy that adds its light to the pixels it covers (no cluster lists).
    LightVolumes,
}

impl PipelineKind {
    /// Every pipeline, in the order the CLI lists them.
    pub const ALL: [PipelineKind; 6] = [
        PipelineKind::NaiveForward,
        PipelineKind::ForwardPlus,
        PipelineKind::ClusteredForward,
        PipelineKind::ClusteredDeferred,
        PipelineKind::TiledDeferred,
        PipelineKind::LightVolumes,
    ];

    /// Name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            PipelineKind::NaiveForward => "naive",
            PipelineKind::ForwardPlus => "forward-plus",
            PipelineKind::ClusteredForward => "clustered-forward",
            PipelineKind::ClusteredDeferred => "clustered-deferred",
            PipelineKind::TiledDeferred => "tiled-deferred",
            PipelineKind::LightVolumes => "light-volumes",
        }
    }

    /// Parses a command-line name.
    pub fn from_name(name: &str) -> Option<PipelineKind> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// True for the pipelines that render a G-buffer and light it afterwards.
    pub fn is_deferred(self) -> bool {
        matches!(
            self,
            PipelineKind::ClusteredDeferred | PipelineKind::TiledDeferred | PipelineKind::LightVolumes
        )
    }

    /// True for pipelines that build light lists per tile or cluster.
    pub fn uses_clusters(self) -> bool {
        matches!(
            self,
            PipelineKind::ForwardPlus
                | PipelineKind::ClusteredForward
                | PipelineKind::ClusteredDeferred
                | PipelineKind::TiledDeferred
        )
    }
}

/// How the deferred pipelines store surfaces (see `shaders/gbuffer.wgsl`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum GBufferLayout {
    /// Four targets: position rgba32f, normal rgba16f (unencoded xyz), albedo rgba16f,
    /// emissive and occlusion rgba16f (+ depth). The normal codec setting does not apply.
    #[default]
    Full,
    /// Two rgba32f targets: (albedo.rgb, n.a) and (position.xyz, n.b), where (n.a, n.b) are the
    /// normal codec's two components, plus emissive and occlusion rgba16f. The albedo channels
    /// carry the material parameters in their integer parts (`shaders/gbuffer.wgsl` explains how).
    Packed,
    /// One rgba32uint target: albedo rgb8 (sRGB-encoded) and the shading model, the normal
    /// codec's 32-bit word, the two material parameters f16, the shading position's depth (f32),
    /// plus emissive and occlusion rgba16f; position reconstructed from that depth.
    Compact,
}

impl GBufferLayout {
    /// Every layout, in CLI order.
    pub const ALL: [GBufferLayout; 3] = [GBufferLayout::Full, GBufferLayout::Packed, GBufferLayout::Compact];

    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            GBufferLayout::Full => "full",
            GBufferLayout::Packed => "packed",
            GBufferLayout::Compact => "compact",
        }
    }

    /// True when the layout can store normals with `codec`: `Full` stores them unencoded (any
    /// codec setting is ignored); `Compact` has 32 bits, which the xyz codec's two f32
    /// components do not fit.
    pub fn supports(self, codec: NormalCodec) -> bool {
        !(self == GBufferLayout::Compact && codec == NormalCodec::Xyz)
    }

    /// True when the layout stores normals with the normal codec (`Packed`, `Compact`).
    pub fn uses_codec(self) -> bool {
        self != GBufferLayout::Full
    }

    /// Parses a command-line name.
    pub fn from_name(name: &str) -> Option<GBufferLayout> {
        Self::ALL.into_iter().find(|l| l.name() == name)
    }

    /// Bytes per pixel of the G-buffer, depth (4 bytes) included.
    pub fn bytes_per_pixel(self) -> u32 {
        match self {
            GBufferLayout::Full => 16 + 8 + 8 + 8 + 4,
            GBufferLayout::Packed => 16 + 16 + 8 + 4,
            GBufferLayout::Compact => 16 + 8 + 4,
        }
    }
}

/// What the debug view shows instead of the tone-mapped image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DebugViewMode {
    /// The normal image.
    #[default]
    None,
    /// Per-pixel number of lights in the pixel's cluster list, as a heatmap with a legend.
    LightCount,
    /// Cluster x index, as alternating colours.
    SliceX,
    /// Cluster y index.
    SliceY,
    /// Cluster z (depth slice) index.
    SliceZ,
    /// Surface albedo (linear, shown through the sRGB output).
    Albedo,
    /// World-space normal mapped to colour (`n * 0.5 + 0.5`).
    Normal,
    /// Linearised view depth (reverse-Z undone), near white to far black.
    Depth,
    /// Clusters whose list hit the per-cluster cap (red) and how full the others are (green).
    Overflow,
    /// PBR metalness, black to white (surfaces of other shading models black).
    Metallic,
    /// PBR perceptual roughness, black to white (surfaces of other shading models black).
    Roughness,
    /// Emitted radiance (linear, clamped to 1).
    Emissive,
    /// Ambient occlusion (white: none).
    Occlusion,
    /// The shadow atlas, fitted to the view: every light's block of tiles (white near the
    /// light, grey at its range on a log scale, black where nothing was drawn).
    ShadowAtlas,
    /// The face edge each pixel's shadowed lights got, as a heatmap: blue at 16 texels, red at
    /// 512 (the mean of their log2 over the lights with a map that reach the pixel; grey where
    /// none does).
    ShadowLod,
}

impl DebugViewMode {
    /// Every view, in CLI order.
    pub const ALL: [DebugViewMode; 15] = [
        DebugViewMode::None,
        DebugViewMode::Albedo,
        DebugViewMode::Normal,
        DebugViewMode::Metallic,
        DebugViewMode::Roughness,
        DebugViewMode::Emissive,
        DebugViewMode::Occlusion,
        DebugViewMode::Depth,
        DebugViewMode::LightCount,
        DebugViewMode::SliceX,
        DebugViewMode::SliceY,
        DebugViewMode::SliceZ,
        DebugViewMode::Overflow,
        DebugViewMode::ShadowAtlas,
        DebugViewMode::ShadowLod,
    ];

    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            DebugViewMode::None => "none",
            DebugViewMode::LightCount => "light-count",
            DebugViewMode::SliceX => "slice-x",
            DebugViewMode::SliceY => "slice-y",
            DebugViewMode::SliceZ => "slice-z",
            DebugViewMode::Albedo => "albedo",
            DebugViewMode::Normal => "normal",
            DebugViewMode::Depth => "depth",
            DebugViewMode::Overflow => "overflow",
            DebugViewMode::Metallic => "metallic",
            DebugViewMode::Roughness => "roughness",
            DebugViewMode::Emissive => "emissive",
            DebugViewMode::Occlusion => "occlusion",
            DebugViewMode::ShadowAtlas => "shadow-atlas",
            DebugViewMode::ShadowLod => "shadow-lod",
        }
    }

    /// Parses a command-line name.
    pub fn from_name(name: &str) -> Option<DebugViewMode> {
        Self::ALL.into_iter().find(|v| v.name() == name)
    }

    /// The id the debug shader switches on.
    pub fn gpu_id(self) -> u32 {
        self as u32
    }

    /// True for views that show cluster data (they need the cluster build).
    pub fn uses_clusters(self) -> bool {
        matches!(
            self,
            DebugViewMode::LightCount
                | DebugViewMode::SliceX
                | DebugViewMode::SliceY
                | DebugViewMode::SliceZ
                | DebugViewMode::Overflow
        )
    }

    /// True for views that show surface attributes (they need a G-buffer).
    pub fn uses_surfaces(self) -> bool {
        matches!(
            self,
            DebugViewMode::Albedo
                | DebugViewMode::Normal
                | DebugViewMode::Metallic
                | DebugViewMode::Roughness
                | DebugViewMode::Emissive
                | DebugViewMode::Occlusion
        )
    }

    /// True for views that show the frame's shadow maps: the frame is planned as without a
    /// debug view (shadow pass and shading included), and the view replaces the tone map.
    pub fn uses_shadows(self) -> bool {
        matches!(self, DebugViewMode::ShadowAtlas | DebugViewMode::ShadowLod)
    }

    /// The next view (wrapping), for key-driven cycling.
    pub fn next(self) -> DebugViewMode {
        let i = Self::ALL.iter().position(|&v| v == self).unwrap_or(0);
        Self::ALL[(i + 1) % Self::ALL.len()]
    }
}

/// Default [`ClusterSettings::coarse_tiles`].
pub const DEFAULT_COARSE_TILES: u32 = 8;

/// How lights are assigned to clusters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterSettings {
    /// Grid sizing and z slicing (Forward+ forces Z = 1).
    pub grid: GridConfig,
    /// Sphere–cluster test.
    pub cull: CullTest,
    /// Optional per-cluster cap; lights beyond it are dropped deterministically and counted.
    /// `None` (the default) is exact: no light is ever dropped.
    pub cap: Option<u32>,
    /// Run a depth pre-pass before clustered forward shading (Forward+ always does).
    pub depth_prepass: bool,
    /// Workgroup size of the cluster-build compute shader (pipeline-override constant).
    pub workgroup_size: u32,
    /// Tiles per coarse-tile edge of the build's first level, which keeps per coarse tile the
    /// lights that can reach any of its tiles, so the tile level tests those instead of every
    /// light (8: 128-px coarse tiles with the default 16-px tiles). Below 2 there is no coarse level; the
    /// planes test never has one (`manylight_core::cluster::coarse_span`). The lists are the
    /// same either way; only the build's cost changes (`docs/benchmarks.md`).
    pub coarse_tiles: u32,
    /// Cut each cluster to the depth range of the pixels in it before its lights are tested
    /// (per-cluster depth bounds, from the depth pre-pass or the G-buffer: `cluster_depth`
    /// pass); clusters no pixel falls in keep no light. Applies where the depth is known before
    /// the build and every shaded fragment is in it: forward pipelines with a depth pre-pass and
    /// the deferred ones, without blended materials (the transparent pass shades fragments the
    /// depth buffer does not hold) and without a debug view (`PlanInputs::bounds_clusters_by_depth`).
    /// On by default (`docs/benchmarks.md`, "Per-cluster depth bounds").
    pub depth_bounds: bool,
    /// Refine the lists per block of `REFINE_EDGE` × `REFINE_EDGE` pixels after the build
    /// (`light_refine` pass): each block keeps the lights of its pixels' cluster lists that
    /// reach the box around its pixels' surface positions, and shades from that list (a block
    /// whose list would be long shades from its cluster lists). Applies where per-cluster depth
    /// bounds can (`PlanInputs::refines_lists`), in every tiled and clustered pipeline but
    /// tiled deferred (which refines its tiles itself). On by default: it wins or breaks even
    /// everywhere measured but with few small lights (`docs/benchmarks.md`, "Refined light
    /// lists").
    pub refined_lists: bool,
}

impl Default for ClusterSettings {
    fn default() -> Self {
        Self {
            grid: GridConfig::default(),
            cull: CullTest::default(),
            cap: None,
            depth_prepass: true,
            workgroup_size: 64,
            coarse_tiles: DEFAULT_COARSE_TILES,
            depth_bounds: true,
            refined_lists: true,
        }
    }
}

impl ClusterSettings {
    /// The grid configuration a pipeline actually uses (Forward+ and tiled deferred have one
    /// depth slice: tiles).
    pub fn grid_for(&self, pipeline: PipelineKind) -> GridConfig {
        let mut grid = self.grid;
        if matches!(pipeline, PipelineKind::ForwardPlus | PipelineKind::TiledDeferred) {
            grid.z_slices = 1;
            if let Some(d) = &mut grid.dims {
                d.z = 1;
            }
        }
        grid
    }
}

/// How frames are rendered. With the `bevy` feature it is a resource: the app's
/// `RenderSettings` is this type, so a new setting is added here only. Changes apply from the
/// next frame.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::prelude::Resource))]
pub struct RenderSettings {
    /// The many-light pipeline.
    pub pipeline: PipelineKind,
    /// The shading model for materials that do not choose one.
    pub shading: ShadingModel,
    /// Multiplier applied before tone mapping, for cameras without an [`Exposure`].
    pub exposure: f32,
    /// Constant ambient term (fraction of albedo).
    pub ambient: f32,
    /// Colour the HDR target is cleared to (linear RGB).
    pub clear_color: [f32; 3],
    /// Cluster grid, culling test, optional cap and depth pre-pass of the tiled and clustered
    /// pipelines.
    pub clusters: ClusterSettings,
    /// G-buffer layout of the deferred pipelines.
    pub gbuffer: GBufferLayout,
    /// Normal encoding of the `Packed` and `Compact` G-buffer layouts.
    pub normal_codec: NormalCodec,
    /// Shadow atlas and face sizes, and whether casting lights cast.
    pub shadows: crate::settings::ShadowSettings,
}

impl RenderSettings {
    /// Refuses values no frame can be rendered with, naming the field: an `exposure` that is
    /// not finite and positive (NaN would give an all-black image with no non-finite pixel
    /// counted), an `ambient` or a `clear_color` channel that is not finite and non-negative.
    pub fn check_values(&self) -> Result<(), String> {
        if !(self.exposure.is_finite() && self.exposure > 0.0) {
            return Err(format!("exposure {} must be finite and positive", self.exposure));
        }
        if !(self.ambient.is_finite() && self.ambient >= 0.0) {
            return Err(format!("ambient {} must be finite and non-negative", self.ambient));
        }
        if !self.clear_color.iter().all(|c| c.is_finite() && *c >= 0.0) {
            return Err(format!("clear_color {:?} must be finite and non-negative", self.clear_color));
        }
        self.shadows.check_values()
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            pipeline: PipelineKind::ClusteredForward,
            shading: ShadingModel::Pbr,
            exposure: 1.0,
            ambient: 0.03,
            clear_color: [0.005, 0.006, 0.01],
            clusters: ClusterSettings::default(),
            gbuffer: GBufferLayout::Full,
            normal_codec: NormalCodec::Octa16,
            shadows: crate::settings::ShadowSettings::default(),
        }
    }
}

/// What a view is rendered with: the [`RenderSettings`] and the debug view (the app's
/// `DebugView` resource, or a camera's `CameraDebugView`). Reads of the render settings go
/// through `Deref` (`settings.pipeline`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSettings {
    /// The render settings.
    pub render: RenderSettings,
    /// Debug view (replaces tone mapping when not `None`).
    pub debug_view: DebugViewMode,
    /// Light count shown as the hottest colour of the light-count heatmap.
    pub debug_heatmap_max: u32,
}

impl Default for FrameSettings {
    fn default() -> Self {
        FrameSettings::from(RenderSettings::default())
    }
}

impl From<RenderSettings> for FrameSettings {
    /// `render` without a debug view.
    fn from(render: RenderSettings) -> Self {
        FrameSettings { render, debug_view: DebugViewMode::None, debug_heatmap_max: 32 }
    }
}

impl std::ops::Deref for FrameSettings {
    type Target = RenderSettings;
    fn deref(&self) -> &RenderSettings {
        &self.render
    }
}

impl std::ops::DerefMut for FrameSettings {
    fn deref_mut(&mut self) -> &mut RenderSettings {
        &mut self.render
    }
}

/// The camera as the render side sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractedCamera {
    /// World-from-camera transform (camera looks down its -Z).
    pub world_from_view: Mat4,
    /// Projection parameters.
    pub projection: Projection,
    /// Last frame's clip-from-world (its camera's placement and projection, at this frame's
    /// viewport, so a resize alone is no motion); `None` on the first frame.
    pub prev_clip_from_world: Option<Mat4>,
    /// Bloom, when the camera has it.
    pub bloom: Option<BloomSettings>,
    /// Camera-motion blur, when the camera has it.
    pub motion_blur: Option<MotionBlurSettings>,
    /// The camera's exposure, when it has one (else `RenderSettings::exposure`).
    pub exposure: Option<Exposure>,
}

impl ExtractedCamera {
    /// True when the camera can be looked through: its transform (and last frame's matrix,
    /// if any) is finite and invertible. A NaN position or a zero scale is not.
    pub fn is_valid(&self) -> bool {
        let det = self.world_from_view.determinant();
        self.world_from_view.is_finite()
            && det.is_finite()
            && det.abs() > f32::MIN_POSITIVE
            && self.prev_clip_from_world.is_none_or(|m| m.is_finite())
    }

    /// View-from-world matrix.
    pub fn view_from_world(&self) -> Mat4 {
        self.world_from_view.inverse()
    }

    /// Clip-from-world for a viewport of `size`.
    pub fn clip_from_world(&self, size: UVec2) -> Mat4 {
        self.projection.matrix(aspect(size)) * self.view_from_world()
    }

    /// Camera position in world space.
    pub fn position(&self) -> Vec3 {
        self.world_from_view.w_axis.truncate()
    }
}

/// Width / height, 1 for an empty viewport.
pub fn aspect(size: UVec2) -> f32 {
    if size.x == 0 || size.y == 0 { 1.0 } else { size.x as f32 / size.y as f32 }
}

/// One drawn object.
#[derive(Clone, Debug)]
pub struct ExtractedInstance {
    /// Geometry (shared; uploaded once per distinct `Arc`).
    pub mesh: Arc<MeshData>,
    /// Material (shared; one bind group per distinct `Arc`).
    pub material: Arc<MaterialData>,
    /// World-from-object transform.
    pub world_from_local: Mat4,
}

/// One point light.
#[derive(Clone, Debug, PartialEq)]
pub struct ExtractedPointLight {
    /// World position.
    pub position: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Luminous intensity in candela, multiplying `color`.
    pub intensity: f32,
    /// Radius of influence (contribution is exactly 0 at and beyond it).
    pub radius: f32,
    /// The cone of a spot light (`None`: a point light, lighting every direction).
    pub spot: Option<SpotCone>,
    /// The light casts shadows, with these biases (`None`: it lights through everything).
    pub shadow: Option<ShadowBias>,
    /// The light moves and flickers on the GPU (`None`: it stays as extracted): each frame a
    /// compute pass writes its position and colour at [`FrameSnapshot::elapsed_secs`] into the
    /// light buffer (`shaders/light_animation.wgsl`), so its motion costs the CPU nothing.
    /// `position` and `color` are then unused; `intensity`, `radius` and `spot` still apply.
    pub animation: Option<Arc<manylight_core::AnimatedLight>>,
}

/// Lights in each chunk of a [`PointLights`] list (the last chunk may hold fewer).
pub const LIGHT_CHUNK: usize = 1024;

/// The point and spot lights of a frame, in chunks of [`LIGHT_CHUNK`] shared between frames
/// (`Arc`): extraction copies a chunk only when one of its lights changed, and the renderer
/// packs and uploads only the lights of chunks that are not the ones it uploaded before. A
/// light's index is its position in the list, which is its index in the light buffer, the
/// lists and the shadow table (an invalid light keeps its place there, lighting nothing).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointLights {
    chunks: Vec<Arc<LightChunk>>,
    len: usize,
}

/// [`LIGHT_CHUNK`] consecutive lights of a [`PointLights`] list, and how many of them cast
/// shadows or animate on the GPU (so a frame finds them without visiting the others).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightChunk {
    lights: Vec<ExtractedPointLight>,
    shadowed: usize,
    animated: usize,
}

impl LightChunk {
    /// The chunk's lights.
    pub fn lights(&self) -> &[ExtractedPointLight] {
        &self.lights
    }

    /// How many of them cast shadows.
    pub fn shadowed(&self) -> usize {
        self.shadowed
    }

    /// How many of them animate on the GPU ([`ExtractedPointLight::animation`]).
    pub fn animated(&self) -> usize {
        self.animated
    }

    fn recount(&mut self) {
        self.shadowed = self.lights.iter().filter(|l| l.shadow.is_some()).count();
        self.animated = self.lights.iter().filter(|l| l.animation.is_some()).count();
    }

    /// Counts `light` in (`add`) or out.
    fn count(&mut self, light: &ExtractedPointLight, add: bool) {
        let (shadowed, animated) =
            (usize::from(light.shadow.is_some()), usize::from(light.animation.is_some()));
        if add {
            self.shadowed += shadowed;
            self.animated += animated;
        } else {
            self.shadowed -= shadowed;
            self.animated -= animated;
        }
    }
}

impl PointLights {
    /// An empty list.
    pub fn new() -> PointLights {
        PointLights::default()
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when there is no light.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The chunks, in order: light `i` is light `i % LIGHT_CHUNK` of chunk `i / LIGHT_CHUNK`.
    pub fn chunks(&self) -> &[Arc<LightChunk>] {
        &self.chunks
    }

    /// Light `i`, if there is one.
    pub fn get(&self, i: usize) -> Option<&ExtractedPointLight> {
        self.chunks.get(i / LIGHT_CHUNK).and_then(|c| c.lights.get(i % LIGHT_CHUNK))
    }

    /// Every light, in order.
    pub fn iter(&self) -> impl Iterator<Item = &ExtractedPointLight> {
        self.chunks.iter().flat_map(|c| c.lights.iter())
    }

    /// How many lights animate on the GPU (one visit per chunk).
    pub fn animated(&self) -> usize {
        self.chunks.iter().map(|c| c.animated).sum()
    }

    /// The lights that cast shadows, with their index, visiting only the chunks that hold some.
    pub fn shadowed(&self) -> impl Iterator<Item = (usize, &ExtractedPointLight)> {
        self.chunks.iter().enumerate().filter(|(_, c)| c.shadowed > 0).flat_map(|(k, c)| {
            c.lights
                .iter()
                .enumerate()
                .filter(|(_, l)| l.shadow.is_some())
                .map(move |(i, l)| (k * LIGHT_CHUNK + i, l))
        })
    }

    /// Adds a light at the end.
    pub fn push(&mut self, light: ExtractedPointLight) {
        if self.len.is_multiple_of(LIGHT_CHUNK) {
            let lights = Vec::with_capacity(LIGHT_CHUNK);
            self.chunks.push(Arc::new(LightChunk { lights, shadowed: 0, animated: 0 }));
        }
        let chunk = Arc::make_mut(self.chunks.last_mut().expect("a chunk with room"));
        chunk.count(&light, true);
        chunk.lights.push(light);
        self.len += 1;
    }

    /// Replaces light `i` (copying its chunk if another frame still holds it); false when
    /// there is no light `i`. A light equal to the one there leaves the chunk shared.
    pub fn set(&mut self, i: usize, light: ExtractedPointLight) -> bool {
        let Some(chunk) = self.chunks.get_mut(i / LIGHT_CHUNK) else { return false };
        match chunk.lights.get(i % LIGHT_CHUNK) {
            None => false,
            Some(old) if *old == light => true,
            Some(_) => {
                let chunk = Arc::make_mut(chunk);
                chunk.count(&light, true);
                let old = std::mem::replace(&mut chunk.lights[i % LIGHT_CHUNK], light);
                chunk.count(&old, false);
                true
            }
        }
    }

    /// Removes the last light and returns it.
    pub fn pop(&mut self) -> Option<ExtractedPointLight> {
        let chunk = self.chunks.last_mut()?;
        let light = Arc::make_mut(chunk).lights.pop();
        if chunk.lights.is_empty() {
            self.chunks.pop();
        } else if let Some(light) = &light {
            Arc::make_mut(chunk).count(light, false);
        }
        self.len -= usize::from(light.is_some());
        light
    }

    /// Changes every light with `f`, in place.
    pub fn update(&mut self, mut f: impl FnMut(&mut ExtractedPointLight)) {
        for chunk in &mut self.chunks {
            let chunk = Arc::make_mut(chunk);
            chunk.lights.iter_mut().for_each(&mut f);
            chunk.recount();
        }
    }
}

impl FromIterator<ExtractedPointLight> for PointLights {
    fn from_iter<I: IntoIterator<Item = ExtractedPointLight>>(lights: I) -> PointLights {
        let mut list = PointLights::new();
        lights.into_iter().for_each(|l| list.push(l));
        list
    }
}

impl From<Vec<ExtractedPointLight>> for PointLights {
    fn from(lights: Vec<ExtractedPointLight>) -> PointLights {
        lights.into_iter().collect()
    }
}

impl<'a> IntoIterator for &'a PointLights {
    type Item = &'a ExtractedPointLight;
    type IntoIter = Box<dyn Iterator<Item = &'a ExtractedPointLight> + 'a>;
    fn into_iter(self) -> Self::IntoIter {
        Box::new(self.iter())
    }
}

impl std::ops::Index<usize> for PointLights {
    type Output = ExtractedPointLight;
    fn index(&self, i: usize) -> &ExtractedPointLight {
        self.get(i).unwrap_or_else(|| panic!("light {i} of {}", self.len))
    }
}

/// How a light's shadow test keeps a surface from shadowing itself (Bevy's
/// `shadow_depth_bias` and `shadow_normal_bias`): the shaded point moves `normal` texels of the
/// light's shadow map off the surface towards the light, and `depth` world units nearer to
/// it along the ray. Larger values remove acne and detach shadows from their casters
/// (peter-panning).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowBias {
    /// World units along the ray from the light.
    pub depth: f32,
    /// Texels of the shadow map at the shaded point, along the surface normal.
    pub normal: f32,
}

impl ShadowBias {
    /// Bevy's `PointLight` defaults.
    pub const POINT: ShadowBias = ShadowBias { depth: 0.08, normal: 0.6 };
    /// Bevy's `SpotLight` defaults.
    pub const SPOT: ShadowBias = ShadowBias { depth: 0.02, normal: 1.8 };
    /// Bevy's `DirectionalLight` defaults.
    pub const DIRECTIONAL: ShadowBias = ShadowBias { depth: 0.02, normal: 1.8 };

    /// True when both biases are finite and not negative.
    pub fn is_valid(&self) -> bool {
        self.depth.is_finite() && self.normal.is_finite() && self.depth >= 0.0 && self.normal >= 0.0
    }
}

impl Default for ShadowBias {
    fn default() -> Self {
        ShadowBias::POINT
    }
}

impl ExtractedPointLight {
    /// A point light (no cone, no shadow, no animation).
    pub fn point(position: Vec3, color: Vec3, intensity: f32, radius: f32) -> ExtractedPointLight {
        ExtractedPointLight { position, color, intensity, radius, spot: None, shadow: None, animation: None }
    }

    /// True when every parameter is finite, the radius and intensity are not negative, and the
    /// emitted colour (`color × intensity`) does not overflow to infinity; for an animated
    /// light, also the box its orbit and bob stay in, and its base colour with twice the room.
    pub fn is_valid(&self) -> bool {
        self.position.is_finite()
            && self.color.is_finite()
            && self.intensity.is_finite()
            && (self.color * self.intensity).is_finite()
            && self.radius.is_finite()
            && self.radius >= 0.0
            && self.intensity >= 0.0
            && self.shadow.is_none_or(|b| b.is_valid())
            && self
                .animation
                .as_deref()
                .is_none_or(|a| a.position_bounds().is_some() && (a.color * self.intensity * 2.0).is_finite())
    }

    /// The box holding the light's position at every time: its position, or the box its
    /// animation stays in.
    pub fn position_bounds(&self) -> (Vec3, Vec3) {
        self.animation.as_deref().and_then(|a| a.position_bounds()).unwrap_or((self.position, self.position))
    }
}

/// A texture a view renders into instead of the main target; the app reads its image back
/// after the frame (render to texture). Ids are chosen by the app and only compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default, serde::Serialize)]
pub struct RenderTextureId(pub u64);

/// Where a view's image goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ViewTarget {
    /// The frame's main target: the window, or the headless image.
    #[default]
    Main,
    /// An offscreen texture of `size` pixels, read back for the app after the frame.
    Texture {
        /// Which texture (views with the same id draw into one texture).
        id: RenderTextureId,
        /// Its size in pixels.
        size: UVec2,
    },
}

/// A rectangle of a target, in pixels from its top-left corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewRect {
    /// Top-left corner.
    pub origin: UVec2,
    /// Width and height.
    pub size: UVec2,
}

/// Components an app copied from a view's camera for its own passes (in `manylight_app`,
/// `ExtractCameraComponentPlugin`), by type: a pass's `plan` function finds its settings here
/// (`PlanInputs::components`) and adds its pass only to the views that carry them.
#[derive(Clone, Default)]
pub struct ViewComponents {
    entries: Vec<ViewComponent>,
}

/// One extracted component: its type, its name for messages and its value.
#[derive(Clone)]
struct ViewComponent {
    type_id: std::any::TypeId,
    name: &'static str,
    value: Arc<dyn std::any::Any + Send + Sync>,
}

impl ViewComponents {
    /// Adds `component`, replacing one of the same type.
    pub fn insert<C: std::any::Any + Send + Sync>(&mut self, component: C) {
        let type_id = std::any::TypeId::of::<C>();
        let entry = ViewComponent { type_id, name: std::any::type_name::<C>(), value: Arc::new(component) };
        match self.entries.iter_mut().find(|e| e.type_id == type_id) {
            Some(old) => *old = entry,
            None => self.entries.push(entry),
        }
    }

    /// The component of type `C`, if the camera carried one.
    pub fn get<C: std::any::Any>(&self) -> Option<&C> {
        let type_id = std::any::TypeId::of::<C>();
        self.entries.iter().find(|e| e.type_id == type_id).and_then(|e| e.value.downcast_ref())
    }

    /// True when no component was extracted.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

impl std::fmt::Debug for ViewComponents {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.entries.iter().map(|e| e.name)).finish()
    }
}

impl PartialEq for ViewComponents {
    /// The same types holding the same values (the same extracted `Arc`s).
    fn eq(&self, other: &Self) -> bool {
        self.entries.len() == other.entries.len()
            && self
                .entries
                .iter()
                .zip(&other.entries)
                .all(|(a, b)| a.type_id == b.type_id && Arc::ptr_eq(&a.value, &b.value))
    }
}

/// One camera's view of the frame: where it looks from, where its image goes and what it
/// shows. Views share the frame's lights and instances, which are uploaded once.
#[derive(Clone, Debug, PartialEq)]
pub struct ExtractedView {
    /// The camera, with its post-processing components.
    pub camera: ExtractedCamera,
    /// The target the view draws into.
    pub target: ViewTarget,
    /// The part of the target it covers; `None` for the whole target. Clipped to the target.
    pub rect: Option<ViewRect>,
    /// The view's own debug view, instead of the frame's [`FrameSettings::debug_view`].
    pub debug_view: Option<DebugViewMode>,
    /// Render order (lower first, as Bevy's `Camera::order`); views with equal order keep
    /// their order in [`FrameSnapshot::views`]. Reported in [`crate::stats::ViewReport`].
    pub order: isize,
    /// The view shows shadows (its camera's [`crate::CameraShadows`]); `false` shades it
    /// unshadowed.
    pub shadows: bool,
    /// Components an app extracted from the camera for its own passes.
    pub components: ViewComponents,
}

impl ExtractedView {
    /// A view of the whole main target through `camera`.
    pub fn main(camera: ExtractedCamera) -> ExtractedView {
        ExtractedView {
            camera,
            target: ViewTarget::Main,
            rect: None,
            debug_view: None,
            order: 0,
            shadows: true,
            components: ViewComponents::default(),
        }
    }

    /// The size of the view's target, given the main target's.
    pub fn target_size(&self, main: UVec2) -> UVec2 {
        match self.target {
            ViewTarget::Main => main,
            ViewTarget::Texture { size, .. } => size,
        }
    }

    /// The rectangle it covers, clipped to a target of `target_size` (zero-sized when it
    /// lies outside).
    pub fn rect_in(&self, target_size: UVec2) -> ViewRect {
        let rect = self.rect.unwrap_or(ViewRect { origin: UVec2::ZERO, size: target_size });
        let origin = rect.origin.min(target_size);
        let end = rect.origin.saturating_add(rect.size).min(target_size);
        ViewRect { origin, size: end - origin }
    }
}

/// One view as the render side draws it: the camera, the size of its image and the settings
/// with its debug view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderView {
    /// Position in [`FrameSnapshot::views`] (the view's cluster buffers are kept by it).
    pub index: usize,
    /// The camera; `None` for a frame without views (only the clear colour).
    pub camera: Option<ExtractedCamera>,
    /// Image size in pixels.
    pub size: UVec2,
    /// The frame's settings, with the view's debug view.
    pub settings: FrameSettings,
}

impl RenderView {
    /// What the HDR image is multiplied by before tone mapping: the camera's [`Exposure`], or
    /// the settings' multiplier for a camera without one.
    pub fn exposure(&self) -> f32 {
        self.camera.and_then(|c| c.exposure).map_or(self.settings.render.exposure, |e| e.multiplier())
    }

    /// True when the view needs the cluster build: a tiled/clustered pipeline with lights
    /// (`has_lights`) and no debug view, or a debug view that shows cluster data.
    pub fn needs_clusters(&self, has_lights: bool) -> bool {
        // A debug view replaces the image: then only a view of cluster data needs them.
        self.camera.is_some()
            && match self.settings.debug_view {
                DebugViewMode::None => self.settings.pipeline.uses_clusters() && has_lights,
                view if view.uses_shadows() => self.settings.pipeline.uses_clusters() && has_lights,
                view => view.uses_clusters(),
            }
    }
}

/// Everything one frame is rendered from.
#[derive(Clone, Debug, Default)]
pub struct FrameSnapshot {
    /// Frame counter, from 0.
    pub frame_index: u64,
    /// Main target size in pixels (0 in either axis: nothing is drawn into it).
    pub viewport: UVec2,
    /// The views, rendered in this order (extract sorts them by [`ExtractedView::order`]);
    /// none renders nothing but the clear colour.
    pub views: Vec<ExtractedView>,
    /// Drawn objects.
    pub instances: Vec<ExtractedInstance>,
    /// Point and spot lights.
    pub lights: PointLights,
    /// Directional lights (not clustered; at most `MAX_DIRECTIONAL_LIGHTS` are drawn, the rest
    /// dropped and counted).
    pub directional_lights: Vec<ExtractedDirectionalLight>,
    /// Settings.
    pub settings: FrameSettings,
    /// Exact per-pixel light lists made outside the renderer (the oracle of `manylight bench
    /// --oracle`, from `manylight_core::efficiency::exact_pixel_lists`): a view that shades
    /// with clusters skips the cluster build and reads these instead, over a grid of one-pixel
    /// tiles and one depth slice (`ranges[x + y * width]`, indices into
    /// [`FrameSnapshot::lights`]). For a single view. `None` (the default): the cluster build
    /// makes the lists.
    pub pixel_light_lists: Option<Arc<manylight_core::cluster::ClusterAssignment>>,
    /// CPU time the main world took to extract this snapshot, in milliseconds (0 for a snapshot
    /// made without an app); reported as `CpuPhases::extract_ms`.
    pub extract_cpu_ms: f64,
    /// Seconds since the app started (Bevy's `Time::elapsed_secs`): the time at which the
    /// lights with an [`ExtractedPointLight::animation`] are shown.
    pub elapsed_secs: f32,
}

/// A directional light as extracted for rendering: light travelling along `direction`
/// everywhere (the sun).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractedDirectionalLight {
    /// Unit direction the light travels, from the light into the scene.
    pub direction: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Illuminance (lux in glTF), multiplying `color`.
    pub illuminance: f32,
    /// The light casts shadows (`None`: it lights through everything).
    pub shadow: Option<DirectionalShadow>,
}

/// A directional light's shadow: its biases (the normal bias in texels of the cascade at the
/// point) and how its cascades split the view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalShadow {
    /// Depth and normal bias.
    pub bias: ShadowBias,
    /// The cascades.
    pub cascades: crate::settings::CascadeShadowConfig,
}

impl Default for DirectionalShadow {
    fn default() -> Self {
        DirectionalShadow { bias: ShadowBias::DIRECTIONAL, cascades: Default::default() }
    }
}

impl ExtractedDirectionalLight {
    /// True when every parameter is finite, the direction is not zero, the illuminance is not
    /// negative and `color × illuminance` does not overflow.
    pub fn is_valid(&self) -> bool {
        self.direction.is_finite()
            && self.direction.length_squared() > 0.0
            && self.color.is_finite()
            && self.illuminance.is_finite()
            && self.illuminance >= 0.0
            && (self.color * self.illuminance).is_finite()
    }
}

impl FrameSnapshot {
    /// The first view's camera.
    pub fn camera(&self) -> Option<&ExtractedCamera> {
        self.views.first().map(|v| &v.camera)
    }

    /// The first view's camera, to change it.
    pub fn camera_mut(&mut self) -> Option<&mut ExtractedCamera> {
        self.views.first_mut().map(|v| &mut v.camera)
    }

    /// Makes `camera` the frame's only view, of the whole main target (`None`: no view).
    pub fn set_camera(&mut self, camera: Option<ExtractedCamera>) {
        self.views.clear();
        self.views.extend(camera.map(ExtractedView::main));
    }

    /// View `index` as the render side draws it (its image size, its debug view).
    pub fn render_view(&self, index: usize) -> RenderView {
        let mut settings = self.settings;
        match self.views.get(index) {
            Some(view) => {
                settings.debug_view = view.debug_view.unwrap_or(settings.debug_view);
                settings.render.shadows.enabled &= view.shadows;
                let size = view.rect_in(view.target_size(self.viewport)).size;
                RenderView { index, camera: Some(view.camera), size, settings }
            }
            None => RenderView { index, camera: None, size: self.viewport, settings },
        }
    }

    /// Removes the views whose camera [`ExtractedCamera::is_valid`] refuses and returns how
    /// many were removed, for [`crate::FrameReport::invalid_cameras`].
    pub fn reject_invalid_camera(&mut self) -> u32 {
        let before = self.views.len();
        self.views.retain(|v| v.camera.is_valid());
        let removed = (before - self.views.len()) as u32;
        if removed > 0 {
            tracing::warn!(
                "{removed} camera(s) with a transform that is not finite or not invertible: not rendered this frame"
            );
        }
        removed
    }

    /// Cameras whose projection [`Projection::sanitized`](manylight_core::Projection::sanitized)
    /// changes, for [`crate::FrameReport::sanitized_cameras`].
    pub fn sanitized_cameras(&self) -> u32 {
        let changed = self
            .views
            .iter()
            .filter(|v| {
                // Compared bit for bit, so a NaN parameter counts as changed; an orthographic
                // projection ignores its field of view.
                let bits = |p: manylight_core::Projection| match p.kind {
                    manylight_core::ProjectionKind::Perspective => {
                        (0, p.fov_y.to_bits(), p.near.to_bits(), p.far.to_bits())
                    }
                    manylight_core::ProjectionKind::Orthographic { height } => {
                        (1, height.to_bits(), p.near.to_bits(), p.far.to_bits())
                    }
                };
                bits(v.camera.projection) != bits(v.camera.projection.sanitized())
            })
            .count() as u32;
        if changed > 0 {
            tracing::debug!("{changed} camera projection(s) were sanitised to render");
        }
        changed
    }

    /// True when at least one light has valid parameters.
    pub fn has_lights(&self) -> bool {
        self.lights.iter().any(|l| l.is_valid())
    }

    /// True when the frame draws shadow maps: shadows are enabled, a view shows them, and a
    /// valid point or spot light with a range, or a valid directional light, casts one.
    pub fn casts_shadows(&self) -> bool {
        self.settings.shadows.enabled
            && self.views.iter().any(|v| v.shadows)
            && (self.lights.shadowed().any(|(_, l)| l.is_valid() && l.radius > 0.0)
                || self.directional_lights.iter().any(|l| l.shadow.is_some() && l.is_valid()))
    }

    /// True when an instance's material is blended (`AlphaMode::Blend`): the frame needs the
    /// transparent pass.
    pub fn has_blended(&self) -> bool {
        self.instances.iter().any(|i| i.material.alpha_mode == manylight_core::AlphaMode::Blend)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each chunk counts its shadowed and animated lights through every change, so a frame
    /// finds them (and knows whether any light animates) from one count per chunk.
    #[test]
    fn light_chunks_count_their_shadowed_and_animated_lights() {
        let plain = ExtractedPointLight {
            position: Vec3::ZERO,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: 1.0,
            spot: None,
            shadow: None,
            animation: None,
        };
        let motion = manylight_core::AnimatedLight {
            center: Vec3::ONE,
            orbit_radius: 1.0,
            orbit_speed: 0.5,
            phase: 0.0,
            bob_amplitude: 0.2,
            bob_speed: 1.0,
            color: Vec3::ONE,
            flicker_speed: 1.0,
            intensity: 1.0,
            radius: 1.0,
        };
        let animated = ExtractedPointLight { animation: Some(Arc::new(motion)), ..plain.clone() };
        let shadowed = ExtractedPointLight { shadow: Some(ShadowBias::POINT), ..plain.clone() };
        let mut lights: PointLights = (0..LIGHT_CHUNK + 10).map(|_| plain.clone()).collect();
        let recount = |l: &PointLights| {
            let animated = l.iter().filter(|l| l.animation.is_some()).count();
            (l.animated(), l.shadowed().count(), animated, l.iter().filter(|l| l.shadow.is_some()).count())
        };
        assert_eq!(recount(&lights), (0, 0, 0, 0));
        lights.set(3, animated.clone());
        lights.set(LIGHT_CHUNK + 2, animated.clone());
        lights.set(LIGHT_CHUNK + 9, shadowed.clone());
        assert_eq!(recount(&lights), (2, 1, 2, 1));
        lights.set(3, shadowed.clone());
        assert_eq!(recount(&lights), (1, 2, 1, 2));
        assert_eq!(lights.pop(), Some(shadowed));
        lights.push(animated);
        assert_eq!(recount(&lights), (2, 1, 2, 1));
        lights.update(|l| l.animation = None);
        assert_eq!(recount(&lights), (0, 1, 0, 1));
        assert_eq!(lights.chunks().iter().map(|c| c.animated()).sum::<usize>(), 0);
    }

    /// An exposure of NaN would render an all-black frame with no non-finite pixel counted:
    /// values no frame can render with are refused, naming the field.
    #[test]
    fn settings_no_frame_can_render_with_are_refused_by_name() {
        assert_eq!(RenderSettings::default().check_values(), Ok(()));
        let cases = [
            (RenderSettings { exposure: f32::NAN, ..Default::default() }, "exposure"),
            (RenderSettings { exposure: 0.0, ..Default::default() }, "exposure"),
            (RenderSettings { exposure: f32::INFINITY, ..Default::default() }, "exposure"),
            (RenderSettings { ambient: -0.1, ..Default::default() }, "ambient"),
            (RenderSettings { ambient: f32::NAN, ..Default::default() }, "ambient"),
            (RenderSettings { clear_color: [0.0, f32::INFINITY, 0.0], ..Default::default() }, "clear_color"),
        ];
        for (settings, field) in cases {
            let message = settings.check_values().expect_err(field);
            assert!(message.starts_with(field), "{message}");
        }
    }
}
