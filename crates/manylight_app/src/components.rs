//! The components a user spawns: where things are, what is drawn, what emits light.

pub use bevy_color::Color;
use bevy_color::LinearRgba;
use bevy_ecs::prelude::*;
use glam::{Mat4, Quat, Vec3};
use manylight_core::{MaterialData, MeshData};
/// A camera's shadows checkbox (`enabled: false`: its view is shaded unshadowed).
pub use manylight_render::settings::CameraShadows;
/// How a directional light's shadow splits the view (Bevy's `CascadeShadowConfig`): a
/// component on the light's entity.
pub use manylight_render::settings::{CascadeShadowConfig, CascadeShadowConfigBuilder};
use manylight_render::snapshot::{DirectionalShadow, ShadowBias};
use std::sync::Arc;

pub use bevy_transform::components::{GlobalTransform, Transform};

/// `color`'s linear RGB, as the shading multiplies it with a light's intensity.
pub fn linear_rgb(color: Color) -> Vec3 {
    let c = LinearRgba::from(color);
    Vec3::new(c.red, c.green, c.blue)
}

/// A light colour from linear RGB (glTF's and the light rigs' colours are linear).
pub fn from_linear_rgb(rgb: Vec3) -> Color {
    Color::linear_rgb(rgb.x, rgb.y, rgb.z)
}

/// Decomposes a matrix (e.g. a glTF node's world matrix) into a [`Transform`]. Unlike
/// `Transform::from_matrix`, a singular matrix (a zero scale on some axes, of the node or a
/// parent) keeps its zero scales and a valid rotation, where a plain decomposition divides by
/// zero and gives NaN; shear is lost.
pub fn transform_from_matrix(m: Mat4) -> Transform {
    let translation = m.w_axis.truncate();
    let m3 = glam::Mat3::from_mat4(m);
    let mut scale = Vec3::new(m3.x_axis.length(), m3.y_axis.length(), m3.z_axis.length());
    if m3.determinant() < 0.0 {
        scale.x = -scale.x;
    }
    let axis = |col: Vec3, s: f32| (s != 0.0 && s.is_finite()).then(|| col / s);
    let (x, y, z) = (axis(m3.x_axis, scale.x), axis(m3.y_axis, scale.y), axis(m3.z_axis, scale.z));
    // Axes of zero length are completed to a right-handed orthonormal frame.
    let (x, y, z) = match (x, y, z) {
        (Some(x), Some(y), Some(z)) => (x, y, z),
        (None, Some(y), Some(z)) => (y.cross(z), y, z),
        (Some(x), None, Some(z)) => (x, z.cross(x), z),
        (Some(x), Some(y), None) => (x, y, x.cross(y)),
        (Some(x), None, None) => {
            let y = x.any_orthonormal_vector();
            (x, y, x.cross(y))
        }
        (None, Some(y), None) => {
            let z = y.any_orthonormal_vector();
            (y.cross(z), y, z)
        }
        (None, None, Some(z)) => {
            let x = z.any_orthonormal_vector();
            (x, z.cross(x), z)
        }
        (None, None, None) => (Vec3::X, Vec3::Y, Vec3::Z),
    };
    let rotation = Quat::from_mat3(&glam::Mat3::from_cols(x, y, z)).normalize();
    Transform { translation, rotation, scale }
}

/// Whether an entity is drawn or lights the scene, as Bevy's `Visibility`: `Inherited` (the
/// default) follows the parent (`ChildOf`), `Hidden` hides the entity and its descendants,
/// `Visible` shows it whatever its parent says. Hidden meshes and lights are not extracted and
/// cost nothing on the render side. The plugin computes [`InheritedVisibility`] from it in
/// `PostUpdate`.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[require(InheritedVisibility)]
pub enum Visibility {
    /// As the parent; visible for an entity without one.
    #[default]
    Inherited,
    /// Hidden, with every descendant that inherits.
    Hidden,
    /// Visible, whatever the parent.
    Visible,
}

/// Whether an entity is visible once its ancestors' [`Visibility`] is taken into account
/// (written by the plugin in `PostUpdate`, after transform propagation; read by extract).
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
pub struct InheritedVisibility(pub bool);

impl Default for InheritedVisibility {
    fn default() -> Self {
        InheritedVisibility(true)
    }
}

/// Where, into which part and in what order a camera renders, as Bevy's `Camera`. Every
/// [`Camera3d`] has one (the default: the whole main target, order 0). Each active camera
/// renders its own view, with its own clusters and light lists, its own post-processing
/// components ([`Bloom`], [`MotionBlur`]) and debug view ([`CameraDebugView`]); the frame's
/// lights are uploaded once and shared by all views.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Render order: lower first; a later camera draws over an earlier one where their
    /// viewports overlap. Equal orders render in query order.
    pub order: isize,
    /// The part of the target it draws into; `None` for the whole target.
    pub viewport: Option<Viewport>,
    /// The window (or headless image), or an offscreen image the app reads.
    pub target: RenderTarget,
    /// An inactive camera renders nothing and costs nothing.
    pub is_active: bool,
}

impl Default for Camera {
    fn default() -> Self {
        Camera { order: 0, viewport: None, target: RenderTarget::Window, is_active: true }
    }
}

/// A rectangle of a camera's target in physical pixels, as Bevy's `Viewport`. The parts of
/// the target no camera covers show the clear colour. A viewport reaching past the target is
/// clipped to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Viewport {
    /// Top-left corner, from the target's top-left.
    pub physical_position: glam::UVec2,
    /// Width and height.
    pub physical_size: glam::UVec2,
}

/// What a camera renders into, as Bevy's `RenderTarget`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RenderTarget {
    /// The window, or the headless image.
    #[default]
    Window,
    /// An offscreen image: after each frame it is read back and put into
    /// [`RenderedImages`](crate::RenderedImages) for the app (render to texture).
    Image(RenderImage),
}

/// An offscreen image a camera renders into; copy it into as many cameras as should draw into
/// the same image. Its pixels arrive in [`RenderedImages`](crate::RenderedImages).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RenderImage {
    /// Its id on the render side.
    pub id: manylight_render::RenderTextureId,
    /// Its size in pixels (1 to the GPU's largest texture size on each axis).
    pub size: glam::UVec2,
}

impl RenderImage {
    /// A new image of `width × height` pixels, with an id no other image of this process has.
    pub fn new(width: u32, height: u32) -> RenderImage {
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
        let id = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        RenderImage { id: manylight_render::RenderTextureId(id), size: glam::UVec2::new(width, height) }
    }
}

/// A debug view for this camera only, instead of the [`DebugView`](crate::DebugView)
/// resource's (e.g. one split-screen half showing light counts).
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
pub struct CameraDebugView(pub manylight_render::DebugViewMode);

/// A 3D camera, as Bevy's: the entity's [`GlobalTransform`] places it (looking down its -Z; its
/// scale is ignored), its [`Projection`] says how it sees (perspective by default), its
/// [`Camera`] where it renders.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[require(Transform, Camera, Projection)]
pub struct Camera3d;

/// How a [`Camera3d`] projects the scene, as Bevy's `Projection`: perspective (the default) or
/// orthographic. Both keep reverse-Z depth; clusters of an orthographic view are boxes sliced
/// linearly in depth.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Rays from the camera through the pixels.
    Perspective(PerspectiveProjection),
    /// Parallel rays.
    Orthographic(OrthographicProjection),
}

impl Default for Projection {
    fn default() -> Self {
        Projection::Perspective(PerspectiveProjection::default())
    }
}

/// A perspective projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerspectiveProjection {
    /// Vertical field of view in radians.
    pub fov: f32,
    /// Near plane distance.
    pub near: f32,
    /// Far plane distance, or `f32::INFINITY` for none (nothing is clipped far away; the
    /// cluster grid then slices up to the farthest light's reach).
    pub far: f32,
}

impl Default for PerspectiveProjection {
    fn default() -> Self {
        let p = manylight_core::Projection::default();
        PerspectiveProjection { fov: p.fov_y, near: p.near, far: p.far }
    }
}

/// An orthographic projection: `viewport_height` world units fill the view vertically (Bevy's
/// `ScalingMode::FixedVertical`), the width follows the view's aspect ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrthographicProjection {
    /// Near plane distance (> 0).
    pub near: f32,
    /// Far plane distance (finite, > near: orthographic depth is linear).
    pub far: f32,
    /// Visible height in world units.
    pub viewport_height: f32,
}

impl Default for OrthographicProjection {
    fn default() -> Self {
        OrthographicProjection { near: 0.1, far: 1000.0, viewport_height: 10.0 }
    }
}

impl From<manylight_core::Projection> for Projection {
    fn from(p: manylight_core::Projection) -> Self {
        match p.kind {
            manylight_core::ProjectionKind::Perspective => {
                Projection::Perspective(PerspectiveProjection { fov: p.fov_y, near: p.near, far: p.far })
            }
            manylight_core::ProjectionKind::Orthographic { height } => {
                Projection::Orthographic(OrthographicProjection {
                    near: p.near,
                    far: p.far,
                    viewport_height: height,
                })
            }
        }
    }
}

impl Projection {
    /// The render side's parameters.
    pub fn params(&self) -> manylight_core::Projection {
        match *self {
            Projection::Perspective(p) => manylight_core::Projection::perspective(p.fov, p.near, p.far),
            Projection::Orthographic(o) => {
                manylight_core::Projection::orthographic(o.viewport_height, o.near, o.far)
            }
        }
    }
}

/// A point light at the entity's [`GlobalTransform`] translation, in Bevy's words and units:
/// `intensity` is the luminous power in lumens (emitted evenly in every direction, so the
/// shading uses `intensity / 4π` candela), `range` the cut-off distance, `radius` the size of
/// the emitter. With a camera without [`Exposure`], a few hundred lumens light a room-sized
/// scene (glTF's and the Khronos viewer's scale); Bevy's default of a million lumens wants
/// [`Exposure::BLENDER`].
///
/// ```
/// use manylight_app::prelude::*;
/// let mut world = World::new();
/// // Warm light, 3 m reach, casting a shadow.
/// let light = PointLight {
///     color: Color::srgb(1.0, 0.8, 0.6),
///     intensity: 800.0,
///     range: 3.0,
///     shadows_enabled: true,
///     ..default()
/// };
/// world.spawn((Transform::from_xyz(0.0, 2.0, 0.0), light));
/// assert!(light.shadow().is_some());
/// ```
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[require(Transform, Visibility)]
pub struct PointLight {
    /// Colour (Bevy's `Color`, in any space; the shading uses its linear RGB).
    pub color: Color,
    /// Luminous power in lumens (multiplies `color`).
    pub intensity: f32,
    /// Distance at which the contribution reaches exactly zero (the light's sphere of
    /// influence, which the cluster build culls with).
    pub range: f32,
    /// Radius of the emitting sphere. Kept for Bevy's vocabulary; the shading treats every
    /// light as a point, so it does not change the image.
    pub radius: f32,
    /// The light casts shadows (a cube of six faces in the shadow atlas; off by default, as in
    /// Bevy).
    pub shadows_enabled: bool,
    /// World units the shadow test moves the shaded point towards the light (against acne).
    pub shadow_depth_bias: f32,
    /// Shadow-map texels the shadow test moves the shaded point off the surface along its
    /// normal (against acne on surfaces at grazing angles).
    pub shadow_normal_bias: f32,
}

impl PointLight {
    /// Bevy's default `shadow_depth_bias` of a point light.
    pub const DEFAULT_SHADOW_DEPTH_BIAS: f32 = ShadowBias::POINT.depth;
    /// Bevy's default `shadow_normal_bias` of a point light.
    pub const DEFAULT_SHADOW_NORMAL_BIAS: f32 = ShadowBias::POINT.normal;

    /// The light's shadow biases when it casts.
    pub fn shadow(&self) -> Option<ShadowBias> {
        self.shadows_enabled
            .then_some(ShadowBias { depth: self.shadow_depth_bias, normal: self.shadow_normal_bias })
    }
}

impl Default for PointLight {
    fn default() -> Self {
        Self {
            color: Color::WHITE,
            intensity: 800.0,
            range: 10.0,
            radius: 0.0,
            shadows_enabled: false,
            shadow_depth_bias: Self::DEFAULT_SHADOW_DEPTH_BIAS,
            shadow_normal_bias: Self::DEFAULT_SHADOW_NORMAL_BIAS,
        }
    }
}

/// A light shining in a cone down the entity's local -Z (its [`GlobalTransform`]'s forward), in
/// Bevy's words: full strength within `inner_angle` of the axis, fading to exactly zero at
/// `outer_angle` (glTF `KHR_lights_punctual` spot lights). The cluster build culls it with the
/// sphere around its cone, smaller than a point light's of the same `range`. `intensity` is in
/// lumens and converted to candela as Bevy does, as if the light shone in every direction
/// (`intensity / 4π`): narrowing the cone does not brighten it.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[require(Transform, Visibility)]
pub struct SpotLight {
    /// Colour (Bevy's `Color`, in any space; the shading uses its linear RGB).
    pub color: Color,
    /// Luminous power in lumens (multiplies `color`).
    pub intensity: f32,
    /// Distance at which the contribution reaches exactly zero.
    pub range: f32,
    /// Radius of the emitter (not used by the shading, as for [`PointLight`]).
    pub radius: f32,
    /// Angle from the axis, in radians, within which the light is at full strength.
    pub inner_angle: f32,
    /// Angle from the axis, in radians, at which the light reaches zero (at most π/2).
    pub outer_angle: f32,
    /// The light casts shadows (off by default, as in Bevy).
    pub shadows_enabled: bool,
    /// World units the shadow test moves the shaded point towards the light.
    pub shadow_depth_bias: f32,
    /// Shadow-map texels the shadow test moves the shaded point off the surface.
    pub shadow_normal_bias: f32,
}

impl SpotLight {
    /// Bevy's default `shadow_depth_bias` of a spot light.
    pub const DEFAULT_SHADOW_DEPTH_BIAS: f32 = ShadowBias::SPOT.depth;
    /// Bevy's default `shadow_normal_bias` of a spot light.
    pub const DEFAULT_SHADOW_NORMAL_BIAS: f32 = ShadowBias::SPOT.normal;

    /// The light's shadow biases when it casts.
    pub fn shadow(&self) -> Option<ShadowBias> {
        self.shadows_enabled
            .then_some(ShadowBias { depth: self.shadow_depth_bias, normal: self.shadow_normal_bias })
    }
}

impl Default for SpotLight {
    fn default() -> Self {
        Self {
            color: Color::WHITE,
            intensity: 800.0,
            range: 10.0,
            radius: 0.0,
            inner_angle: 0.0,
            outer_angle: std::f32::consts::FRAC_PI_4,
            shadows_enabled: false,
            shadow_depth_bias: Self::DEFAULT_SHADOW_DEPTH_BIAS,
            shadow_normal_bias: Self::DEFAULT_SHADOW_NORMAL_BIAS,
        }
    }
}

/// A light travelling down the entity's local -Z everywhere (the sun), in Bevy's words:
/// `illuminance` (lux for glTF's directional lights) times `color`. Not clustered: every pixel
/// evaluates every directional light, up to `MAX_DIRECTIONAL_LIGHTS` (8) per frame; more are
/// dropped and counted (`FrameReport::dropped_directional_lights`).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[require(Transform, Visibility)]
pub struct DirectionalLight {
    /// Colour (Bevy's `Color`, in any space; the shading uses its linear RGB).
    pub color: Color,
    /// Illuminance in lux, multiplying `color`.
    pub illuminance: f32,
    /// Casts shadows: cascades of orthographic maps fitted to the view, split as the entity's
    /// [`CascadeShadowConfig`] says (the default without one).
    pub shadows_enabled: bool,
    /// World units the shadow test moves the shaded point towards the light.
    pub shadow_depth_bias: f32,
    /// Shadow-map texels the shadow test moves the shaded point off the surface.
    pub shadow_normal_bias: f32,
}

impl DirectionalLight {
    /// Bevy's default `shadow_depth_bias` of a directional light.
    pub const DEFAULT_SHADOW_DEPTH_BIAS: f32 = ShadowBias::DIRECTIONAL.depth;
    /// Bevy's default `shadow_normal_bias` of a directional light.
    pub const DEFAULT_SHADOW_NORMAL_BIAS: f32 = ShadowBias::DIRECTIONAL.normal;

    /// The light's shadow, split by `cascades`, when it casts.
    pub fn shadow(&self, cascades: CascadeShadowConfig) -> Option<DirectionalShadow> {
        self.shadows_enabled.then_some(DirectionalShadow {
            bias: ShadowBias { depth: self.shadow_depth_bias, normal: self.shadow_normal_bias },
            cascades,
        })
    }
}

impl Default for DirectionalLight {
    fn default() -> Self {
        Self {
            color: Color::WHITE,
            illuminance: 1.0,
            shadows_enabled: false,
            shadow_depth_bias: Self::DEFAULT_SHADOW_DEPTH_BIAS,
            shadow_normal_bias: Self::DEFAULT_SHADOW_NORMAL_BIAS,
        }
    }
}

/// The geometry drawn at the entity's [`GlobalTransform`] (shared; uploaded once per `Arc`).
#[derive(Component, Clone, Debug)]
#[require(Transform, Visibility)]
pub struct Mesh3d(pub Arc<MeshData>);

/// The material of a [`Mesh3d`] entity (shared; one GPU binding per `Arc`).
#[derive(Component, Clone, Debug)]
pub struct Material(pub Arc<MaterialData>);

/// Animates a light: the plugin moves its [`Transform`] (relative to its parent, if it has one)
/// and tints its [`PointLight`] each frame, by [`bevy_time::Time`]; with
/// [`LightAnimationMode::Gpu`](crate::LightAnimationMode::Gpu) a compute pass does it instead,
/// on the light buffer, for the lights it can take.
#[derive(Component, Clone, Copy, Debug)]
pub struct LightAnimation(pub manylight_scene::AnimatedLight);

/// Bloom on the camera (bright pass, blur, added before tone mapping): the render crate's
/// [`BloomSettings`](manylight_render::BloomSettings) itself, a component (no mirror to keep in
/// step). A camera without it gets no bloom passes and no bloom textures.
pub type Bloom = manylight_render::BloomSettings;

/// The camera's exposure (EV100), Bevy's `Exposure`: the render crate's
/// [`Exposure`](manylight_render::Exposure) itself, a component. A camera without it uses
/// `RenderSettings::exposure` (a multiplier, 1 by default).
pub type Exposure = manylight_render::Exposure;

/// Image-based lighting on what the camera sees, Bevy's `EnvironmentMapLight`: the render
/// crate's [`EnvironmentMapLight`](manylight_render::EnvironmentMapLight) itself, a component.
/// A camera without it gets no environment bindings and no prefiltering.
pub type EnvironmentMapLight = manylight_render::EnvironmentMapLight;

/// A panorama behind the camera's geometry, Bevy's `Skybox`: the render crate's
/// [`Skybox`](manylight_render::Skybox) itself, a component. A camera without it shows the
/// clear colour.
pub type Skybox = manylight_render::Skybox;

/// Camera-motion blur on the camera: the render crate's
/// [`MotionBlurSettings`](manylight_render::MotionBlurSettings) itself, a component. A camera
/// without it gets no motion-blur pass.
pub type MotionBlur = manylight_render::MotionBlurSettings;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_matrix_gives_back_the_matrix_also_when_it_is_singular() {
        let rotation = Quat::from_euler(glam::EulerRot::YXZ, 0.7, -0.3, 1.1);
        let translation = Vec3::new(1.0, -2.0, 3.0);
        for scale in [
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(-1.0, 2.0, 3.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::ZERO,
        ] {
            let m = Mat4::from_scale_rotation_translation(scale, rotation, translation);
            let t = transform_from_matrix(m);
            assert!(t.rotation.is_finite() && t.scale.is_finite(), "{scale}: {t:?}");
            assert!(t.to_matrix().abs_diff_eq(m, 1e-5), "{scale}: {:?} vs {m:?}", t.to_matrix());
        }
    }
}
