//! What the debug view shows instead of the tone-mapped image, and which frame data each view
//! needs.

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
