//! Which many-light pipeline renders a frame and how it is set up: the pipeline, the deferred
//! pipelines' G-buffer layout, and how lights are assigned to clusters.

use manylight_core::cluster::{CullTest, GridConfig};
use manylight_core::codec::NormalCodec;

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

/// Written as its name (`"clustered-forward"`, …), as the CLI takes it.
impl serde::Serialize for PipelineKind {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
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
