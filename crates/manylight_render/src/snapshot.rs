//! The plain data one frame is rendered from. The app's extract system fills it from the ECS
//! world; the render side reads it and nothing else (it never reaches back into the ECS).
//!
//! The snapshot's cameras, views and instances are defined here; its lights in
//! [`crate::lights`] and its settings in [`crate::settings`], re-exported here so that
//! `snapshot::X` names every part of a snapshot.

use glam::{Mat4, UVec2, Vec3};
use manylight_core::{MaterialData, MeshData, Projection};
use std::sync::Arc;

pub use crate::lights::{
    DirectionalShadow, ExtractedDirectionalLight, ExtractedPointLight, LIGHT_CHUNK, LightChunk, PointLights,
    ShadowBias,
};
pub use crate::settings::{
    BloomChain, BloomSettings, ClusterSettings, DEFAULT_COARSE_TILES, DebugViewMode, EnvironmentFilter,
    EnvironmentHandle, EnvironmentImages, EnvironmentMapLight, Exposure, FrameSettings, GBufferLayout,
    MotionBlurSettings, PipelineKind, RenderSettings, Skybox,
};

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
    /// The environment that lights what the camera sees, when it has one.
    pub environment: Option<EnvironmentMapLight>,
    /// The panorama behind the geometry, when the camera has one (else the clear colour).
    pub skybox: Option<Skybox>,
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
    /// The panoramas the views' environments and skyboxes name (at least those; the renderer
    /// prefilters each handle once and frees its maps when no view names it).
    pub environments: EnvironmentImages,
    /// CPU time the main world took to extract this snapshot, in milliseconds (0 for a snapshot
    /// made without an app); reported as `CpuPhases::extract_ms`.
    pub extract_cpu_ms: f64,
    /// Seconds since the app started (Bevy's `Time::elapsed_secs`): the time at which the
    /// lights with an [`ExtractedPointLight::animation`] are shown.
    pub elapsed_secs: f32,
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

    /// True when the frame draws shadow maps: a light casts ([`FrameSnapshot::casts_shadows`])
    /// and shadows are found with maps ([`crate::settings::ShadowMethod::Maps`]).
    pub fn draws_shadow_maps(&self) -> bool {
        self.settings.shadows.method == crate::settings::ShadowMethod::Maps && self.casts_shadows()
    }

    /// True when the frame traces shadow rays: a light casts ([`FrameSnapshot::casts_shadows`])
    /// and shadows are found with rays ([`crate::settings::ShadowMethod::Rays`]).
    pub fn traces_shadow_rays(&self) -> bool {
        self.settings.shadows.method == crate::settings::ShadowMethod::Rays && self.casts_shadows()
    }

    /// True when the frame has shadows: shadows are enabled, a view shows them, and a valid
    /// point or spot light with a range, or a valid directional light, casts one.
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
