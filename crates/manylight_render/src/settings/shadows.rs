//! How shadows are drawn and what they took: the atlas and face sizes, the filter, a
//! directional light's cascades, the constants the atlas layout shares with the shaders, and
//! the frame's shadow counters.

/// How shadow maps are sized (part of [`RenderSettings`](super::RenderSettings)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowSettings {
    /// Lights that cast shadows cast them; `false` renders every light unshadowed (no atlas, no
    /// pass), whatever the lights say. A camera's shadows checkbox.
    pub enabled: bool,
    /// Largest edge of the atlas in texels (a power of two; default 4096, 64 MiB at most,
    /// reached only when the lights ask for that much: the atlas grows from 256 as they do).
    /// A device with a smaller `max_texture_dimension_2d` gets its own limit, counted in
    /// [`ShadowReport::atlas_limited_by_device`]. What each size costs and how close it comes
    /// to exact visibility: `manylight report --shadows` (docs/benchmarks.md, "Shadows").
    pub atlas_size: u32,
    /// Largest face edge a light gets (a power of two).
    pub max_face_size: u32,
    /// Smallest face edge a casting light gets (a power of two): below it, a light goes
    /// without a shadow and is counted.
    pub min_face_size: u32,
    /// Face texels asked per pixel of the light sphere's projected radius.
    pub resolution_scale: f32,
    /// Edge of each cascade of a directional light (a power of two; a light's cascades share
    /// one block of 3 × 2 tiles, so a smaller atlas gets smaller cascades).
    pub cascade_size: u32,
    /// Keep a light's map from the frame before when nothing it holds changed: the light (its
    /// position, range, block in the atlas and the faces a view meets) and the casters drawn
    /// into it (their meshes and transforms). Cached maps cost no draw; turning this off draws
    /// every map every frame (the same image).
    pub cache_maps: bool,
    /// Most point or spot light maps drawn again in a frame when their light or casters
    /// changed (`None`: every one; default 256). The rest, least important (smallest on
    /// screen) first, keep the map of an earlier frame and are tested from where their light
    /// was when it was drawn (counted in [`ShadowReport::maps_stale`]). Lights new to the atlas
    /// or moved in it, and directional lights, are always drawn. At 1 000 moving lights the
    /// default draws a third of the maps a frame at the same visibility error as drawing all
    /// (`manylight report --shadows`, docs/benchmarks.md, "Shadow settings").
    pub max_redrawn_maps: Option<u32>,
    /// The filter of every lookup.
    pub filter: ShadowFilteringMethod,
    /// How a casting light's visibility is found: shadow maps in an atlas (the default), or
    /// rays traced through the scene's BVH.
    pub method: ShadowMethod,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        ShadowSettings {
            enabled: true,
            atlas_size: 4096,
            max_face_size: 512,
            min_face_size: 16,
            resolution_scale: 1.0,
            cascade_size: 1024,
            cache_maps: true,
            max_redrawn_maps: Some(256),
            filter: ShadowFilteringMethod::Hardware2x2,
            method: ShadowMethod::Maps,
        }
    }
}

impl ShadowSettings {
    /// Refuses sizes no atlas can be planned with, naming the field.
    pub fn check_values(&self) -> Result<(), String> {
        for (name, value) in [
            ("shadows.atlas_size", self.atlas_size),
            ("shadows.max_face_size", self.max_face_size),
            ("shadows.min_face_size", self.min_face_size),
            ("shadows.cascade_size", self.cascade_size),
        ] {
            if !value.is_power_of_two() {
                return Err(format!("{name} {value} must be a power of two"));
            }
        }
        if self.min_face_size > self.max_face_size {
            return Err(format!(
                "shadows.min_face_size {} must not exceed shadows.max_face_size {}",
                self.min_face_size, self.max_face_size
            ));
        }
        if self.atlas_size < SHADOW_TILE_COLUMNS * self.min_face_size {
            return Err(format!(
                "shadows.atlas_size {} cannot hold one light at shadows.min_face_size {} ({} texels wide)",
                self.atlas_size,
                self.min_face_size,
                SHADOW_TILE_COLUMNS * self.min_face_size
            ));
        }
        if !(self.resolution_scale.is_finite() && self.resolution_scale > 0.0) {
            return Err(format!(
                "shadows.resolution_scale {} must be finite and positive",
                self.resolution_scale
            ));
        }
        if self.max_redrawn_maps == Some(0) {
            return Err("shadows.max_redrawn_maps must be at least 1 (None draws every changed map)".into());
        }
        Ok(())
    }
}

/// How a casting light's visibility is found (part of [`ShadowSettings`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ShadowMethod {
    /// A shadow map per light in one atlas, drawn by the shadow pass and read with the
    /// [`ShadowSettings::filter`] in shading. The atlas and face settings apply.
    #[default]
    Maps,
    /// A ray from every shaded point to every casting light that reaches it, traced in the
    /// shading pass through a two-level BVH of the scene's opaque meshes (built when a light
    /// casts, the instance level again when an instance moves): exact visibility, hard
    /// shadows, no atlas and no shadow pass. Its cost grows with pixels × lights a pixel.
    Rays,
}

impl ShadowMethod {
    /// Every method.
    pub const ALL: [ShadowMethod; 2] = [ShadowMethod::Maps, ShadowMethod::Rays];

    /// Name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            ShadowMethod::Maps => "maps",
            ShadowMethod::Rays => "rays",
        }
    }
}

/// How a shadow map is filtered where it is read (Bevy's `ShadowFilteringMethod`, as a frame
/// setting).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ShadowFilteringMethod {
    /// One comparison sample: the hardware's bilinear 2 × 2 filter.
    #[default]
    Hardware2x2,
    /// Four comparison samples half a texel apart: a 3 × 3 texel tent (weights 1 2 1), softer
    /// edges for four lookups.
    Gaussian,
}

impl ShadowFilteringMethod {
    /// Every method.
    pub const ALL: [ShadowFilteringMethod; 2] =
        [ShadowFilteringMethod::Hardware2x2, ShadowFilteringMethod::Gaussian];

    /// Name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            ShadowFilteringMethod::Hardware2x2 => "hardware2x2",
            ShadowFilteringMethod::Gaussian => "gaussian",
        }
    }

    /// The id the shaders read (`GpuShadowLight::tile.w`, `GpuCascade::tile.w`).
    pub fn gpu_id(self) -> u32 {
        match self {
            ShadowFilteringMethod::Hardware2x2 => 0,
            ShadowFilteringMethod::Gaussian => 1,
        }
    }
}

/// What the frame's shadows took, in the stats JSON and the overlay.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ShadowReport {
    /// Lights that asked for a shadow.
    pub casting_lights: u32,
    /// Lights whose maps were drawn this frame (a point or spot light's six faces, a
    /// directional light's cascades); the others in the atlas are cached or stale.
    pub maps_rendered: u32,
    /// Cascades drawn for the directional lights.
    pub cascades_rendered: u32,
    /// Casting lights that no view sees (their sphere is outside every view): no map, and no
    /// pixel needs one.
    pub unseen_lights: u32,
    /// Cube faces of mapped lights that no view sees: left undrawn (no visible pixel reads them).
    pub unseen_faces: u32,
    /// Lights whose maps were kept from the frame before because nothing they hold changed
    /// ([`ShadowSettings::cache_maps`]): no draw.
    pub maps_cached: u32,
    /// Lights whose light or casters changed but whose map was kept from an earlier frame
    /// because [`ShadowSettings::max_redrawn_maps`] were drawn already: tested from where the
    /// light was when its map was drawn.
    pub maps_stale: u32,
    /// (instance, face) pairs drawn.
    pub instance_faces: u32,
    /// Draw calls of the shadow pass (one per mesh).
    pub draw_calls: u32,
    /// Edge of the atlas texture in texels.
    pub atlas_size: u32,
    /// Bytes of the atlas texture.
    pub atlas_bytes: u64,
    /// Fraction of the atlas's texels in a light's tiles.
    pub atlas_occupancy: f32,
    /// Lights that got a smaller face than they asked for (the atlas was full).
    pub downgraded_lights: u32,
    /// Lights that got no shadow map at all (no room even at the smallest face): lit unshadowed.
    pub dropped_lights: u32,
    /// The device's texture limit is below [`ShadowSettings::atlas_size`]: the atlas is the
    /// device's largest.
    pub atlas_limited_by_device: bool,
}

/// Most cascades a directional light's shadow has (they share one block of
/// [`SHADOW_FACES`] tiles).
pub const MAX_CASCADES: usize = 4;

/// How a directional light's shadow is split along the view into cascades, each an
/// orthographic map fitted to its slice of the camera's frustum (Bevy's
/// `CascadeShadowConfig`; build one with [`CascadeShadowConfigBuilder`]). With the `bevy`
/// feature it is a component: put it on a `DirectionalLight`'s entity (without one, the
/// default).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::component::Component))]
pub struct CascadeShadowConfig {
    /// The far bound of each cascade (view-space distance along the camera's axis), increasing;
    /// only the first `count` are used. Past the last, nothing is shadowed.
    pub bounds: [f32; MAX_CASCADES],
    /// Cascades in use, 1 to [`MAX_CASCADES`].
    pub count: u32,
    /// Fraction of the previous cascade's far bound by which each cascade reaches nearer, so
    /// neighbouring cascades overlap.
    pub overlap_proportion: f32,
    /// Where the first cascade starts.
    pub minimum_distance: f32,
}

impl Default for CascadeShadowConfig {
    fn default() -> Self {
        CascadeShadowConfigBuilder::default().build().unwrap_or(CascadeShadowConfig {
            bounds: [150.0; MAX_CASCADES],
            count: 1,
            overlap_proportion: 0.2,
            minimum_distance: 0.1,
        })
    }
}

impl CascadeShadowConfig {
    /// The used far bounds.
    pub fn far_bounds(&self) -> &[f32] {
        &self.bounds[..(self.count as usize).clamp(1, MAX_CASCADES)]
    }

    /// Where cascade `i` starts: the minimum distance for the first, the previous far bound
    /// less the overlap for the others.
    pub fn near_bound(&self, i: usize) -> f32 {
        match i {
            0 => self.minimum_distance,
            _ => self.bounds[i - 1] * (1.0 - self.overlap_proportion),
        }
    }
}

/// Builds a [`CascadeShadowConfig`] as Bevy's builder does: the first cascade ends at
/// `first_cascade_far_bound`, the others grow geometrically to `maximum_distance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeShadowConfigBuilder {
    /// Cascades, 1 to [`MAX_CASCADES`] (default 4).
    pub num_cascades: usize,
    /// Where the first cascade starts (default 0.1).
    pub minimum_distance: f32,
    /// Where the last cascade ends: nothing further is shadowed (default 150).
    pub maximum_distance: f32,
    /// Where the first cascade ends (default 5).
    pub first_cascade_far_bound: f32,
    /// How far each cascade reaches into the previous one, as a fraction of its far bound
    /// (default 0.2).
    pub overlap_proportion: f32,
}

impl Default for CascadeShadowConfigBuilder {
    fn default() -> Self {
        CascadeShadowConfigBuilder {
            num_cascades: MAX_CASCADES,
            minimum_distance: 0.1,
            maximum_distance: 150.0,
            first_cascade_far_bound: 5.0,
            overlap_proportion: 0.2,
        }
    }
}

/// A [`CascadeShadowConfigBuilder`] that describes no cascades.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CascadeConfigError {
    /// `num_cascades` is 0 or above [`MAX_CASCADES`].
    #[error("num_cascades {0} must be 1 to {MAX_CASCADES}")]
    Count(usize),
    /// The distances are not finite, positive and increasing.
    #[error(
        "cascade distances must be finite with 0 <= minimum_distance ({minimum}) < first_cascade_far_bound ({first}) <= maximum_distance ({maximum})"
    )]
    Distances {
        /// `minimum_distance`.
        minimum: f32,
        /// `first_cascade_far_bound`.
        first: f32,
        /// `maximum_distance`.
        maximum: f32,
    },
    /// `overlap_proportion` is outside [0, 1).
    #[error("overlap_proportion {0} must be in [0, 1)")]
    Overlap(f32),
}

impl CascadeShadowConfigBuilder {
    /// The configuration, or what is wrong with the builder.
    pub fn build(&self) -> Result<CascadeShadowConfig, CascadeConfigError> {
        let n = self.num_cascades;
        if n == 0 || n > MAX_CASCADES {
            return Err(CascadeConfigError::Count(n));
        }
        let (minimum, first, maximum) =
            (self.minimum_distance, self.first_cascade_far_bound, self.maximum_distance);
        let ordered = minimum >= 0.0 && minimum < first && first <= maximum;
        if !(minimum.is_finite() && first.is_finite() && maximum.is_finite() && ordered) {
            return Err(CascadeConfigError::Distances { minimum, first, maximum });
        }
        if !(0.0..1.0).contains(&self.overlap_proportion) {
            return Err(CascadeConfigError::Overlap(self.overlap_proportion));
        }
        let mut bounds = [maximum; MAX_CASCADES];
        if n > 1 {
            let base = (maximum / first).powf(1.0 / (n - 1) as f32);
            for (i, b) in bounds.iter_mut().take(n).enumerate() {
                *b = first * base.powi(i as i32);
            }
            bounds[n - 1] = maximum;
        }
        Ok(CascadeShadowConfig {
            bounds,
            count: n as u32,
            overlap_proportion: self.overlap_proportion,
            minimum_distance: minimum,
        })
    }
}

/// Cube faces of a point or spot light's shadow map: +X, -X, +Y, -Y, +Z, -Z (face `f` looks
/// down axis `f / 2`, towards + when `f` is even).
pub const SHADOW_FACES: u32 = 6;
/// A light's faces lie in the shadow atlas as a block of this many columns (and
/// `SHADOW_FACES / SHADOW_TILE_COLUMNS` rows) of square tiles.
pub const SHADOW_TILE_COLUMNS: u32 = 3;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cascade_bounds_grow_geometrically_as_bevy_builds_them() {
        let c = CascadeShadowConfig::default();
        assert_eq!(c.count, 4);
        let b = c.far_bounds();
        assert!((b[0] - 5.0).abs() < 1e-5 && (b[3] - 150.0).abs() < 1e-3);
        assert!((b[1] / b[0] - b[2] / b[1]).abs() < 1e-3, "{b:?}");
        assert!((c.near_bound(1) - 4.0).abs() < 1e-5 && c.near_bound(0) == 0.1);
        let one = CascadeShadowConfigBuilder { num_cascades: 1, ..Default::default() }.build().unwrap();
        assert_eq!(one.far_bounds(), &[150.0]);
        let bad = |b: CascadeShadowConfigBuilder| b.build().unwrap_err();
        assert_eq!(
            bad(CascadeShadowConfigBuilder { num_cascades: 5, ..Default::default() }),
            CascadeConfigError::Count(5)
        );
        assert!(matches!(
            bad(CascadeShadowConfigBuilder { first_cascade_far_bound: 200.0, ..Default::default() }),
            CascadeConfigError::Distances { .. }
        ));
        assert!(matches!(
            bad(CascadeShadowConfigBuilder { maximum_distance: f32::NAN, ..Default::default() }),
            CascadeConfigError::Distances { .. }
        ));
        assert_eq!(
            bad(CascadeShadowConfigBuilder { overlap_proportion: 1.0, ..Default::default() }),
            CascadeConfigError::Overlap(1.0)
        );
    }
}
