//! Materials and textures as plain data (what the GPU side uploads once, shared as `Arc`s).

use bevy_color::{Color, ColorToComponents, LinearRgba};
use glam::{Affine2, Vec2, Vec3, Vec4};
use std::sync::Arc;

/// How a surface responds to light. Selected per material or globally in the render settings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ShadingModel {
    /// Diffuse only.
    Lambert,
    /// Diffuse plus a Blinn-Phong specular lobe.
    BlinnPhong,
    /// Cel shading: each light's diffuse term in [`TOON_BANDS`] flat bands, plus a rim light
    /// on silhouettes the light reaches (`shade_reached_light` in `shaders/common/brdf.wgsl`).
    Toon,
    /// glTF 2.0 metallic-roughness: GGX distribution, separable Smith visibility,
    /// Schlick Fresnel and Lambert diffuse, split by metallic ([`crate::brdf`]).
    #[default]
    Pbr,
}

/// Number of flat diffuse bands of [`ShadingModel::Toon`] (shared with WGSL).
pub const TOON_BANDS: u32 = 3;
/// Strength of the toon rim light, as a fraction of the light's diffuse colour.
pub const TOON_RIM_STRENGTH: f32 = 0.5;

impl ShadingModel {
    /// Value the shaders switch on (`SHADING_*` in `shaders/common/brdf.wgsl`).
    pub fn gpu_id(self) -> u32 {
        match self {
            ShadingModel::Lambert => 0,
            ShadingModel::BlinnPhong => 1,
            ShadingModel::Toon => 2,
            ShadingModel::Pbr => 3,
        }
    }

    /// Every model, in `gpu_id` order.
    pub const ALL: [ShadingModel; 4] =
        [ShadingModel::Lambert, ShadingModel::BlinnPhong, ShadingModel::Toon, ShadingModel::Pbr];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ShadingModel::Lambert => "lambert",
            ShadingModel::BlinnPhong => "blinn-phong",
            ShadingModel::Toon => "toon",
            ShadingModel::Pbr => "pbr",
        }
    }

    /// Parses a name written by [`ShadingModel::name`].
    pub fn from_name(name: &str) -> Option<ShadingModel> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// An RGBA8 image, either sRGB-encoded colour or linear data.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureData {
    /// Where it came from (file name or generator), for error messages and GPU labels.
    pub label: String,
    /// Width in pixels (> 0).
    pub width: u32,
    /// Height in pixels (> 0).
    pub height: u32,
    /// `width * height * 4` bytes, rows top to bottom.
    pub rgba8: Vec<u8>,
    /// True when the bytes are sRGB-encoded colour (sampled through an `*Srgb` format).
    pub srgb: bool,
}

/// How a texture repeats outside `[0, 1]` (Bevy's `ImageAddressMode`, glTF `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ImageAddressMode {
    /// The texture tiles.
    #[default]
    Repeat,
    /// The texture tiles, every other copy mirrored.
    MirrorRepeat,
    /// The edge texels extend forever.
    ClampToEdge,
}

/// How texels are filtered (Bevy's `ImageFilterMode`, glTF `magFilter`/`minFilter`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ImageFilterMode {
    /// The nearest texel (or mip level).
    Nearest,
    /// Linear interpolation between texels (or mip levels).
    #[default]
    Linear,
}

/// How a material samples one of its textures (glTF `sampler`; Bevy's
/// `ImageSamplerDescriptor`).
///
/// The default is what glTF leaves to the implementation: repeat, trilinear, and 16×
/// anisotropic filtering where the adapter has it (only when every filter is linear).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureSampler {
    /// Along u.
    pub address_mode_u: ImageAddressMode,
    /// Along v.
    pub address_mode_v: ImageAddressMode,
    /// When a texel covers more than a pixel.
    pub mag_filter: ImageFilterMode,
    /// When a pixel covers more than a texel.
    pub min_filter: ImageFilterMode,
    /// Between mip levels; `None` samples the full-size level only (glTF `NEAREST` and
    /// `LINEAR` minification filters).
    pub mipmap_filter: Option<ImageFilterMode>,
    /// Most samples along a pixel's footprint (1 = no anisotropic filtering, at most
    /// [`MAX_ANISOTROPY`]); honoured when every filter is linear and the adapter filters
    /// anisotropically. On a software rasteriser it is the dearest part of texturing:
    /// `docs/benchmarks.md` measures it on lavapipe.
    pub anisotropy_clamp: u16,
}

/// The largest [`TextureSampler::anisotropy_clamp`] (and the default).
pub const MAX_ANISOTROPY: u16 = 16;

impl Default for TextureSampler {
    fn default() -> Self {
        TextureSampler {
            address_mode_u: ImageAddressMode::Repeat,
            address_mode_v: ImageAddressMode::Repeat,
            mag_filter: ImageFilterMode::Linear,
            min_filter: ImageFilterMode::Linear,
            mipmap_filter: Some(ImageFilterMode::Linear),
            anisotropy_clamp: MAX_ANISOTROPY,
        }
    }
}

impl TextureSampler {
    /// True when the sampler may filter anisotropically: every filter linear, mipmaps on, a
    /// clamp above 1.
    pub fn allows_anisotropy(&self) -> bool {
        self.anisotropy_clamp > 1
            && self.mag_filter == ImageFilterMode::Linear
            && self.min_filter == ImageFilterMode::Linear
            && self.mipmap_filter == Some(ImageFilterMode::Linear)
    }
}

/// Which texture coordinate set of the mesh a texture reads (Bevy's `UvChannel`, glTF
/// `texCoord`): [`Vertex::uv`](crate::Vertex::uv) or [`Vertex::uv1`](crate::Vertex::uv1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum UvChannel {
    /// `TEXCOORD_0`.
    #[default]
    Uv0,
    /// `TEXCOORD_1`.
    Uv1,
}

/// A material's texture: the image, how it is sampled, which uv set it reads and how those
/// uvs are transformed first (`KHR_texture_transform`).
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialTexture {
    /// The pixels (shared between materials).
    pub image: Arc<TextureData>,
    /// Wrap and filter modes.
    pub sampler: TextureSampler,
    /// The uv set.
    pub uv_channel: UvChannel,
    /// Applied to the uvs before sampling: `uv' = uv_transform * uv` (identity by default).
    pub uv_transform: Affine2,
}

impl MaterialTexture {
    /// `image` with the default sampler, `TEXCOORD_0` and no transform.
    pub fn new(image: Arc<TextureData>) -> MaterialTexture {
        MaterialTexture {
            image,
            sampler: TextureSampler::default(),
            uv_channel: UvChannel::Uv0,
            uv_transform: Affine2::IDENTITY,
        }
    }

    /// The transform of glTF's `KHR_texture_transform`: scale, then rotate by `rotation`
    /// radians counter-clockwise in texture space (v points down), then offset.
    pub fn gltf_uv_transform(offset: Vec2, rotation: f32, scale: Vec2) -> Affine2 {
        // glam's angle turns +x towards +y; with v down that is clockwise on the image.
        Affine2::from_scale_angle_translation(scale, -rotation, offset)
    }

    /// The uv the texture is sampled at for a vertex's two uv sets.
    pub fn sample_uv(&self, uv0: Vec2, uv1: Vec2) -> Vec2 {
        let uv = match self.uv_channel {
            UvChannel::Uv0 => uv0,
            UvChannel::Uv1 => uv1,
        };
        self.uv_transform.transform_point2(uv)
    }
}

impl From<Arc<TextureData>> for MaterialTexture {
    fn from(image: Arc<TextureData>) -> MaterialTexture {
        MaterialTexture::new(image)
    }
}

impl From<TextureData> for MaterialTexture {
    fn from(image: TextureData) -> MaterialTexture {
        MaterialTexture::new(Arc::new(image))
    }
}

/// How a material's alpha is used (glTF `alphaMode`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored: the surface is fully opaque.
    #[default]
    Opaque,
    /// Fragments whose alpha (base colour factor times texture) is below the cutoff are
    /// discarded; the rest are opaque.
    Mask(f32),
    /// Alpha blends the surface over what lies behind it ("over", not premultiplied): drawn by
    /// the transparent pass after the opaque surfaces, farthest first (by the centre of each
    /// instance's bounds), lit like forward shading, without writing depth.
    Blend,
}

impl AlphaMode {
    /// glTF's default `alphaCutoff`.
    pub const DEFAULT_CUTOFF: f32 = 0.5;

    /// The cutoff below which fragments are discarded; `None` unless `Mask`. A non-finite
    /// cutoff becomes the default one.
    pub fn cutoff(self) -> Option<f32> {
        match self {
            AlphaMode::Mask(c) if c.is_finite() => Some(c),
            AlphaMode::Mask(_) => Some(Self::DEFAULT_CUTOFF),
            _ => None,
        }
    }
}

/// Surface parameters of a mesh instance. Over 15 fields because it is glTF's material model
/// (factors, five textures, alpha mode, double-sidedness, extensions) plus the shading model:
/// one field per glTF property, as the loader reads them.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialData {
    /// Name for logs and GPU labels.
    pub label: String,
    /// Multiplier of the base colour texture, alpha included (Bevy's `StandardMaterial::base_color`;
    /// shaded in linear RGB, see [`MaterialData::base_color_linear`]).
    pub base_color: Color,
    /// Optional sRGB base colour texture.
    pub base_color_texture: Option<MaterialTexture>,
    /// PBR metalness factor (0 dielectric .. 1 metal).
    pub metallic: f32,
    /// PBR perceptual roughness factor (0 mirror .. 1 rough).
    pub roughness: f32,
    /// Optional linear metallic-roughness texture (glTF: blue = metalness, green =
    /// roughness), multiplied with the factors.
    pub metallic_roughness_texture: Option<MaterialTexture>,
    /// Per-material shading model; `None` uses the global one from the render settings.
    pub shading: Option<ShadingModel>,
    /// Blinn-Phong exponent (the Blinn-Phong and toon models).
    pub shininess: f32,
    /// Strength of the Blinn-Phong specular lobe (0 = none).
    pub specular: f32,
    /// Optional linear tangent-space normal map (glTF: rgb = xyz * 0.5 + 0.5, +y up in
    /// texture space); the mesh's tangents (`Vertex::tangent`) give its frame.
    pub normal_texture: Option<MaterialTexture>,
    /// Scale of the normal map's x and y (glTF `normalTexture.scale`).
    pub normal_scale: f32,
    /// Optional linear ambient-occlusion texture (red channel). Occlusion darkens only the
    /// ambient term, never a point light's contribution (glTF: it applies to indirect light).
    pub occlusion_texture: Option<MaterialTexture>,
    /// How much of the occlusion applies: `1 + strength * (texel - 1)` (0 = none, 1 = full).
    pub occlusion_strength: f32,
    /// Emitted radiance, added whatever the lights (glTF `emissiveFactor` times
    /// `KHR_materials_emissive_strength`; Bevy's `StandardMaterial::emissive`). Alpha is unused.
    pub emissive: LinearRgba,
    /// Optional sRGB emissive texture, multiplied with `emissive`.
    pub emissive_texture: Option<MaterialTexture>,
    /// Drawn from both sides, the normal flipped on back faces; single-sided materials are not
    /// drawn where their back faces the camera (glTF `doubleSided`).
    pub double_sided: bool,
    /// How alpha is used.
    pub alpha_mode: AlphaMode,
}

impl Default for MaterialData {
    fn default() -> Self {
        Self {
            label: "default".into(),
            base_color: Color::WHITE,
            base_color_texture: None,
            metallic: 0.0,
            roughness: 0.5,
            metallic_roughness_texture: None,
            shading: None,
            shininess: 32.0,
            specular: 0.25,
            normal_texture: None,
            normal_scale: 1.0,
            occlusion_texture: None,
            occlusion_strength: 1.0,
            emissive: LinearRgba::BLACK,
            emissive_texture: None,
            // Procedural scenes are open shells seen from either side; glTF materials say.
            double_sided: true,
            alpha_mode: AlphaMode::Opaque,
        }
    }
}

impl MaterialData {
    /// [`MaterialData::base_color`] in linear RGBA, as the shaders use it.
    pub fn base_color_linear(&self) -> Vec4 {
        self.base_color.to_linear().to_vec4()
    }

    /// [`MaterialData::emissive`] as linear RGB, as the shaders use it.
    pub fn emissive_rgb(&self) -> Vec3 {
        self.emissive.to_vec3()
    }

    /// The five texture slots in shader order (`TEXTURE_SLOT_*`: base colour,
    /// metallic-roughness, normal, occlusion, emissive).
    pub fn texture_slots(&self) -> [Option<&MaterialTexture>; 5] {
        [
            self.base_color_texture.as_ref(),
            self.metallic_roughness_texture.as_ref(),
            self.normal_texture.as_ref(),
            self.occlusion_texture.as_ref(),
            self.emissive_texture.as_ref(),
        ]
    }

    /// [`MaterialData::texture_slots`], mutable.
    pub fn texture_slots_mut(&mut self) -> [Option<&mut MaterialTexture>; 5] {
        [
            self.base_color_texture.as_mut(),
            self.metallic_roughness_texture.as_mut(),
            self.normal_texture.as_mut(),
            self.occlusion_texture.as_mut(),
            self.emissive_texture.as_mut(),
        ]
    }

    /// Every texture the material samples.
    pub fn textures(&self) -> impl Iterator<Item = &MaterialTexture> {
        self.texture_slots().into_iter().flatten()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The specification's example: offset (0, 1), a quarter turn and half scale take the
    /// lower left quadrant of the image, turned clockwise.
    #[test]
    fn gltf_uv_transform_matches_the_specification_example() {
        let t = MaterialTexture {
            uv_transform: MaterialTexture::gltf_uv_transform(
                Vec2::new(0.0, 1.0),
                std::f32::consts::FRAC_PI_2,
                Vec2::splat(0.5),
            ),
            ..MaterialTexture::new(Arc::new(TextureData {
                label: "t".into(),
                width: 1,
                height: 1,
                rgba8: vec![255; 4],
                srgb: true,
            }))
        };
        for (uv, expected) in [((0.0, 0.0), (0.0, 1.0)), ((1.0, 0.0), (0.0, 0.5)), ((1.0, 1.0), (0.5, 0.5))] {
            let got = t.sample_uv(Vec2::new(uv.0, uv.1), Vec2::ZERO);
            assert!(got.distance(Vec2::new(expected.0, expected.1)) < 1e-6, "{uv:?}: {got}");
        }
        // The second uv set, untransformed.
        let uv1 = MaterialTexture { uv_channel: UvChannel::Uv1, ..t.clone() };
        assert_eq!(uv1.sample_uv(Vec2::ZERO, Vec2::ZERO), Vec2::new(0.0, 1.0));
        assert!(TextureSampler::default().allows_anisotropy());
        let off = TextureSampler { anisotropy_clamp: 1, ..TextureSampler::default() };
        assert!(!off.allows_anisotropy());
    }
}
