//! The settings a camera carries: bloom, exposure, motion blur and its shadows checkbox. With
//! the `bevy` feature each is a component of the camera's entity (the app uses these types, it
//! does not mirror them); a camera without one gets the default or no pass.

/// Most levels (iterations) of the chain.
pub const MAX_BLOOM_LEVELS: usize = 6;

/// How the blur iterations are laid out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BloomChain {
    /// Each iteration halves the resolution (1/2, 1/4, …); the composite sums every level.
    #[default]
    Downsampled,
    /// Every iteration blurs at full resolution (separable 9-tap: 1×9 then 9×1): the
    /// straightforward layout, several times the cost of the downsampled chain.
    FullResolution,
}

impl BloomChain {
    /// Name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            BloomChain::Downsampled => "downsampled",
            BloomChain::FullResolution => "full-resolution",
        }
    }
}

/// Bloom on a camera: light brighter than `threshold` spreads into its surroundings (bright
/// pass, blur over `iterations`, added to the HDR image before tone mapping). With the `bevy`
/// feature it is a component: the app's `Bloom` is this type, so a new setting is added here
/// only. A camera without it gets no bloom passes and no bloom textures.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::component::Component))]
pub struct BloomSettings {
    /// Brightness (largest channel, after the camera's exposure) where bloom starts.
    pub threshold: f32,
    /// Width of the soft knee below the threshold (0 = hard cut).
    pub knee: f32,
    /// Weight of the blurred light added back to the image.
    pub intensity: f32,
    /// Blur iterations (levels of the chain), 1 to [`MAX_BLOOM_LEVELS`].
    pub iterations: u32,
    /// Downsampled chain or the full-resolution one.
    pub chain: BloomChain,
}

impl Default for BloomSettings {
    fn default() -> Self {
        Self { threshold: 1.0, knee: 0.5, intensity: 0.3, iterations: 5, chain: BloomChain::Downsampled }
    }
}

impl BloomSettings {
    /// Full-resolution separable blur: 1×9 / 9×1 kernels, 5 iterations, every one at the
    /// viewport's size.
    pub fn full_resolution() -> Self {
        Self { chain: BloomChain::FullResolution, iterations: 5, ..Self::default() }
    }

    /// Iterations clamped to what the chain supports (1 to [`MAX_BLOOM_LEVELS`]).
    pub fn levels(&self) -> usize {
        (self.iterations as usize).clamp(1, MAX_BLOOM_LEVELS)
    }

    /// The settings with non-finite or negative values replaced: a NaN or infinite threshold
    /// blooms nothing, a NaN intensity adds nothing (never a NaN pixel).
    pub fn sanitized(&self) -> BloomSettings {
        let finite_or = |v: f32, fallback: f32| if v.is_finite() { v.max(0.0) } else { fallback };
        BloomSettings {
            threshold: finite_or(self.threshold, f32::MAX),
            knee: finite_or(self.knee, 0.0),
            intensity: finite_or(self.intensity, 0.0),
            ..*self
        }
    }
}

/// A camera's exposure in photographic terms, Bevy's `Exposure`: `ev100` is the exposure value
/// at ISO 100, and the HDR image is multiplied by `1 / (1.2 · 2^ev100)` before tone mapping
/// (the saturation-based sensitivity). Use it with lights in physical units (candela, lux,
/// lumens): a sunlit scene wants about [`Exposure::SUNLIGHT`], a lamp-lit room
/// [`Exposure::INDOOR`]. With the `bevy` feature it is a component (the app's `Exposure`); a
/// camera without it uses `RenderSettings::exposure` (a plain multiplier, 1 by default, which
/// suits glTF sample scenes' light values as the Khronos viewer shows them).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::component::Component))]
pub struct Exposure {
    /// Exposure value at ISO 100 (larger: darker image).
    pub ev100: f32,
}

impl Exposure {
    /// Bright sunlight.
    pub const SUNLIGHT: Exposure = Exposure { ev100: 15.0 };
    /// An overcast day.
    pub const OVERCAST: Exposure = Exposure { ev100: 12.0 };
    /// A lamp-lit interior.
    pub const INDOOR: Exposure = Exposure { ev100: 7.0 };
    /// Blender's default camera (Bevy's default).
    pub const BLENDER: Exposure = Exposure { ev100: 9.7 };

    /// The exposure that multiplies the HDR image by `multiplier` (for `multiplier > 0`).
    pub fn from_multiplier(multiplier: f32) -> Exposure {
        Exposure { ev100: -(multiplier * 1.2).log2() }
    }

    /// The multiplier `1 / (1.2 · 2^ev100)`; 1 for a non-finite `ev100`, and always finite
    /// (`ev100` is clamped to ±100).
    pub fn multiplier(&self) -> f32 {
        if !self.ev100.is_finite() {
            return 1.0;
        }
        (-self.ev100.clamp(-100.0, 100.0)).exp2() / 1.2
    }
}

impl Default for Exposure {
    fn default() -> Self {
        Exposure::BLENDER
    }
}

/// Camera-motion blur on a camera: each pixel is blurred along its screen motion since the
/// previous frame (reprojected from depth); a still camera leaves the image unchanged. With the
/// `bevy` feature it is a component: the app's `MotionBlur` is this type. A camera without it
/// gets no motion-blur pass.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::component::Component))]
pub struct MotionBlurSettings {
    /// Taps along the velocity (2 to 64).
    pub samples: u32,
    /// Fraction of the frame-to-frame motion that is blurred (1 = a full-frame shutter).
    pub strength: f32,
    /// Longest blur in pixels (velocities are clamped to it).
    pub max_pixels: f32,
}

impl Default for MotionBlurSettings {
    fn default() -> Self {
        Self { samples: 8, strength: 1.0, max_pixels: 64.0 }
    }
}

/// A camera's shadows checkbox: with `enabled: false` its view shades every light unshadowed
/// (composed without shadow lookups or the atlas binding) while other cameras keep theirs; the
/// frame draws no shadow map when no camera shows shadows. A camera without the component
/// shows them. With the `bevy` feature it is a component of the camera's entity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::component::Component))]
pub struct CameraShadows {
    /// The view shows the shadows of the lights that cast them.
    pub enabled: bool,
}

impl Default for CameraShadows {
    fn default() -> Self {
        CameraShadows { enabled: true }
    }
}
