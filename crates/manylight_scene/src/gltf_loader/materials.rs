//! glTF materials and their images.
//!
//! Images are decoded to sRGB RGBA8 once per distinct source (the same resolved file, the same
//! `data:` URI or the same buffer view), however many `images` entries name it. Dimensions
//! are read from the image header and checked against `LoadOptions::max_texture_size` and
//! the `LoadOptions::max_image_bytes` budget before any pixel is decoded — the decode's peak (a
//! 16-bit source beside its RGBA8 copy) and what stays (RGBA8 with its mip chain) — so a tiny
//! file that declares a huge image, or names one image many times, costs nothing.
//!
//! Colour textures (base colour, emissive) use the sRGB decode; data textures
//! (metallic-roughness, normal, occlusion) use a linear copy of the same pixels, made once per
//! image and also counted against `max_image_bytes`.

use super::uri::{UriSource, is_data_uri, resolve_uri, split_data_uri};
use super::{Ctx, MAX_DOWNSCALED_SOURCE, OversizedTextures, over_budget};
use crate::SceneError;
use glam::{Affine2, Vec2, Vec3, Vec4};
use gltf::json::validation::Checked;
use image::{ImageDecoder, ImageFormat, ImageReader, Limits};
use manylight_core::{
    AlphaMode, Color, ColorToComponents, ImageAddressMode, ImageFilterMode, LinearRgba, MaterialData,
    MaterialTexture, TextureData, TextureSampler, UvChannel,
};
use serde_json::Value;
use std::borrow::Cow;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Largest image file (in bytes) read from a URI; larger files are refused before reading.
const MAX_IMAGE_FILE_BYTES: u64 = 256 << 20;

/// Where an image's encoded bytes come from; images with the same source share one decode.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(super) enum ImageSource<'a> {
    /// A `data:` URI, or a file fetched before the load, by its URI text.
    Data(&'a str),
    /// A file in the glTF file's folder, by its canonical path.
    File(PathBuf),
    /// A buffer view, by index.
    View(usize),
}

/// The lower-cased media type of a `data:` URI, without parameters or `;base64` (empty when
/// it has none).
fn data_media_type(uri: &str) -> String {
    let header = split_data_uri(uri).map_or("", |(h, _)| h);
    header.split(';').next().unwrap_or_default().trim().to_ascii_lowercase()
}

/// Blinn-Phong exponent and specular strength for a metallic-roughness material.
///
/// `shininess = 2 / r^4 - 2` (the Blinn-Phong exponent whose lobe matches a GGX lobe of
/// roughness `r`), clamped to `[1, 512]`; `specular` goes from 0.04 (dielectric) to 1 (metal).
pub fn blinn_phong_from_pbr(roughness: f32, metallic: f32) -> (f32, f32) {
    let r = if roughness.is_finite() { roughness.clamp(0.05, 1.0) } else { 1.0 };
    let m = if metallic.is_finite() { metallic.clamp(0.0, 1.0) } else { 0.0 };
    let shininess = (2.0 / (r * r * r * r) - 2.0).clamp(1.0, 512.0);
    let specular = 0.04 + (1.0 - 0.04) * m;
    (shininess, specular)
}

/// The extension that scales `emissiveFactor` beyond 1.
const EMISSIVE_STRENGTH: &str = "KHR_materials_emissive_strength";
/// The extension that offsets, rotates and scales a texture's uvs.
const TEXTURE_TRANSFORM: &str = "KHR_texture_transform";

/// A material's texture slots in `MaterialData` order: the property's path from the material.
const TEXTURE_SLOTS: [&[&str]; 5] = [
    &["pbrMetallicRoughness", "baseColorTexture"],
    &["pbrMetallicRoughness", "metallicRoughnessTexture"],
    &["normalTexture"],
    &["occlusionTexture"],
    &["emissiveTexture"],
];

/// A `KHR_texture_transform` object of a texture slot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TextureTransformExt {
    /// The uv transform (identity when a value was unusable, with a warning).
    pub transform: Affine2,
    /// Its `texCoord`, which overrides the slot's.
    pub tex_coord: Option<u32>,
}

/// The material extensions that the `gltf` crate drops, of one material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct MaterialExtensions {
    /// `KHR_materials_emissive_strength` `emissiveStrength` (1 when absent).
    pub emissive_strength: f32,
    /// `KHR_texture_transform` of each slot, in [`TEXTURE_SLOTS`] order.
    pub texture_transforms: [Option<TextureTransformExt>; 5],
}

impl Default for MaterialExtensions {
    fn default() -> Self {
        MaterialExtensions { emissive_strength: 1.0, texture_transforms: [None; 5] }
    }
}

/// The `KHR_materials_emissive_strength` and `KHR_texture_transform` values of every
/// material of glTF JSON `json` (already parsed by `gltf`), by material index; empty when the
/// file mentions neither extension. Unusable values fall back to the defaults (strength 1,
/// identity transform) with a warning.
///
/// The `gltf` crate drops these extensions unless its matching features are on, so they are
/// read from the text: the top level is parsed into a map of raw (unparsed) values, so the rest
/// of the document is only scanned, and only the `materials` array is built.
pub(super) fn material_extensions(path: &Path, json: &[u8]) -> Vec<MaterialExtensions> {
    use serde_json::value::RawValue;
    let mentions = |name: &str| json.windows(name.len()).any(|w| w == name.as_bytes());
    if !mentions(EMISSIVE_STRENGTH) && !mentions(TEXTURE_TRANSFORM) {
        return Vec::new();
    }
    let materials = serde_json::from_slice::<HashMap<String, &RawValue>>(json).ok().and_then(|top| {
        let list = top.get("materials")?;
        serde_json::from_str::<Vec<Value>>(list.get()).ok()
    });
    let Some(materials) = materials else {
        tracing::warn!(file = %path.display(), "could not read the materials' extensions, ignored");
        return Vec::new();
    };
    let read = |(index, m): (usize, &Value)| {
        let mut out = MaterialExtensions::default();
        if let Some(ext) = m.get("extensions").and_then(|e| e.get(EMISSIVE_STRENGTH)) {
            match ext.get("emissiveStrength").map(Value::as_f64) {
                None => {}
                Some(Some(v)) if v.is_finite() && v >= 0.0 && (v as f32).is_finite() => {
                    out.emissive_strength = v as f32
                }
                Some(_) => tracing::warn!(
                    file = %path.display(), material = index,
                    "{EMISSIVE_STRENGTH}: emissiveStrength is not a finite non-negative number, using 1"
                ),
            }
        }
        for (slot, names) in TEXTURE_SLOTS.iter().enumerate() {
            let info = names.iter().try_fold(m, |v, name| v.get(name));
            let ext = info.and_then(|i| i.get("extensions")).and_then(|e| e.get(TEXTURE_TRANSFORM));
            if let Some(ext) = ext {
                let property = names.join(".");
                out.texture_transforms[slot] = Some(texture_transform(path, index, &property, ext));
            }
        }
        out
    };
    materials.iter().enumerate().map(read).collect()
}

/// Reads a `KHR_texture_transform` object of property `property` of material `material`.
fn texture_transform(path: &Path, material: usize, property: &str, ext: &Value) -> TextureTransformExt {
    let warn = |what: &str| {
        tracing::warn!(
            file = %path.display(), material,
            "{property} {TEXTURE_TRANSFORM}: {what}, using the default"
        );
    };
    let number = |v: &Value| v.as_f64().map(|x| x as f32).filter(|x| x.is_finite());
    let pair = |name: &str, default: Vec2| match ext.get(name) {
        None => default,
        Some(v) => match v.as_array().map(|a| a.iter().map(number).collect::<Vec<_>>()).as_deref() {
            Some([Some(x), Some(y)]) => Vec2::new(*x, *y),
            _ => {
                warn(&format!("{name} is not two finite numbers"));
                default
            }
        },
    };
    let offset = pair("offset", Vec2::ZERO);
    let scale = pair("scale", Vec2::ONE);
    let rotation = match ext.get("rotation") {
        None => 0.0,
        Some(v) => number(v).unwrap_or_else(|| {
            warn("rotation is not a finite number");
            0.0
        }),
    };
    let tex_coord = match ext.get("texCoord") {
        None => None,
        // Integers may be written as `1.0`.
        Some(v) => match v.as_f64().filter(|x| x.fract() == 0.0 && *x >= 0.0 && *x <= u32::MAX as f64) {
            Some(x) => Some(x as u32),
            None => {
                warn("texCoord is not a non-negative integer");
                None
            }
        },
    };
    let transform = MaterialTexture::gltf_uv_transform(offset, rotation, scale);
    TextureTransformExt { transform, tex_coord }
}

impl<'a> Ctx<'a> {
    /// Converts material `index`: base colour, metallic-roughness, normal, occlusion and
    /// emissive factors and textures, `doubleSided` and `alphaMode`.
    pub(super) fn material(&mut self, index: usize) -> Result<MaterialData, SceneError> {
        let root = self.root;
        let m = &root.materials[index]; // the caller checked the index
        let pbr = &m.pbr_metallic_roughness;
        let mut base = Vec4::from_array(pbr.base_color_factor.0);
        if !base.is_finite() {
            tracing::warn!(file = %self.path.display(), material = index, "non-finite baseColorFactor, using white");
            base = Vec4::ONE;
        }
        let base = base.clamp(Vec4::ZERO, Vec4::splat(f32::MAX));
        // Slots in the order of `TEXTURE_SLOTS`.
        let texture = match &pbr.base_color_texture {
            Some(info) => Some(self.material_texture(index, 0, info.index.value(), info.tex_coord, true)?),
            None => None,
        };
        let metallic_roughness_texture = match &pbr.metallic_roughness_texture {
            Some(info) => Some(self.material_texture(index, 1, info.index.value(), info.tex_coord, false)?),
            None => None,
        };
        let (normal_texture, normal_scale) = match &m.normal_texture {
            Some(info) => {
                let t = self.material_texture(index, 2, info.index.value(), info.tex_coord, false)?;
                (Some(t), self.finite(info.scale, index, "normalTexture.scale", 1.0))
            }
            None => (None, 1.0),
        };
        let (occlusion_texture, occlusion_strength) = match &m.occlusion_texture {
            Some(info) => {
                let t = self.material_texture(index, 3, info.index.value(), info.tex_coord, false)?;
                let strength = self.finite(info.strength.0, index, "occlusionTexture.strength", 1.0);
                (Some(t), strength.clamp(0.0, 1.0))
            }
            None => (None, 1.0),
        };
        let emissive_texture = match &m.emissive_texture {
            Some(info) => Some(self.material_texture(index, 4, info.index.value(), info.tex_coord, true)?),
            None => None,
        };
        let mut emissive = Vec3::from_array(m.emissive_factor.0);
        if !emissive.is_finite() {
            tracing::warn!(file = %self.path.display(), material = index, "non-finite emissiveFactor, using black");
            emissive = Vec3::ZERO;
        }
        let strength = self.material_extensions.get(index).map_or(1.0, |e| e.emissive_strength);
        // Clamped after the product, which may overflow to infinity.
        let emissive = (emissive.max(Vec3::ZERO) * strength).min(Vec3::splat(f32::MAX));
        let factor = |v: f32, name: &str, default: f32| self.finite(v, index, name, default).clamp(0.0, 1.0);
        let metallic = factor(pbr.metallic_factor.0, "metallicFactor", 1.0);
        let roughness = factor(pbr.roughness_factor.0, "roughnessFactor", 1.0);
        let (shininess, specular) = blinn_phong_from_pbr(roughness, metallic);
        let alpha_mode = self.alpha_mode(index);
        Ok(MaterialData {
            label: m.name.clone().unwrap_or_else(|| format!("material {index}")),
            base_color: Color::LinearRgba(LinearRgba::from_vec4(base)),
            base_color_texture: texture,
            metallic,
            roughness,
            metallic_roughness_texture,
            shading: None,
            shininess,
            specular,
            normal_texture,
            normal_scale,
            occlusion_texture,
            occlusion_strength,
            emissive: LinearRgba::from_vec3(emissive),
            emissive_texture,
            double_sided: m.double_sided,
            alpha_mode,
        })
    }

    /// `value`, or `default` with a warning when it is not finite (`name` is the property).
    fn finite(&self, value: f32, material: usize, name: &str, default: f32) -> f32 {
        if value.is_finite() {
            value
        } else {
            tracing::warn!(file = %self.path.display(), material, "non-finite {name}, using {default}");
            default
        }
    }

    /// The `alphaMode` (and `alphaCutoff`) of material `index`.
    fn alpha_mode(&self, index: usize) -> AlphaMode {
        let m = &self.root.materials[index];
        match m.alpha_mode {
            Checked::Valid(gltf::json::material::AlphaMode::Opaque) => AlphaMode::Opaque,
            Checked::Valid(gltf::json::material::AlphaMode::Mask) => {
                let cutoff = m.alpha_cutoff.map_or(AlphaMode::DEFAULT_CUTOFF, |c| c.0);
                let cutoff = self.finite(cutoff, index, "alphaCutoff", AlphaMode::DEFAULT_CUTOFF);
                AlphaMode::Mask(cutoff.max(0.0))
            }
            Checked::Valid(gltf::json::material::AlphaMode::Blend) => AlphaMode::Blend,
            Checked::Invalid => {
                tracing::warn!(file = %self.path.display(), material = index, "unknown alphaMode, using OPAQUE");
                AlphaMode::Opaque
            }
        }
    }

    /// Texture `texture` of slot `slot` (in `TEXTURE_SLOTS` order) of material `material`,
    /// read through `TEXCOORD_<tex_coord>` unless its `KHR_texture_transform` names another
    /// set: the image as sRGB colour or as linear data, its sampler, uv set and uv transform.
    fn material_texture(
        &mut self,
        material: usize,
        slot: usize,
        texture: usize,
        tex_coord: u32,
        srgb: bool,
    ) -> Result<MaterialTexture, SceneError> {
        let root = self.root;
        let property = TEXTURE_SLOTS[slot].last().copied().unwrap_or_default();
        let what = format!("material {material} {property}");
        let tex = self.lookup(&root.textures, texture, &what, "texture")?;
        let sampler = match tex.sampler {
            Some(s) => {
                let what = format!("texture {texture}");
                let s = self.lookup(&root.samplers, s.value(), &what, "sampler")?;
                self.sampler(s, texture)
            }
            None => TextureSampler::default(),
        };
        let ext = self.material_extensions.get(material).and_then(|e| e.texture_transforms[slot]);
        let uv_channel = match ext.and_then(|e| e.tex_coord).unwrap_or(tex_coord) {
            0 => UvChannel::Uv0,
            1 => UvChannel::Uv1,
            n => {
                tracing::warn!(
                    file = %self.path.display(), material,
                    "{property} uses TEXCOORD_{n}; only TEXCOORD_0 and TEXCOORD_1 are loaded, using TEXCOORD_0",
                );
                UvChannel::Uv0
            }
        };
        let image = self.texture_image(tex.source.value(), texture, srgb)?;
        let uv_transform = ext.map_or(Affine2::IDENTITY, |e| e.transform);
        Ok(MaterialTexture { image, sampler, uv_channel, uv_transform })
    }

    /// The wrap and filter modes of glTF sampler `s` (of texture `texture`); unknown values
    /// (already refused by the parser unless lenient) fall back to the defaults.
    fn sampler(&self, s: &gltf::json::texture::Sampler, texture: usize) -> TextureSampler {
        use gltf::json::texture::{MagFilter, MinFilter, WrappingMode};
        let warn = |what: &str| {
            tracing::warn!(file = %self.path.display(), texture, "sampler has an unknown {what}, using the default");
        };
        let address = |mode: &Checked<WrappingMode>, what: &str| match mode {
            Checked::Valid(WrappingMode::Repeat) => ImageAddressMode::Repeat,
            Checked::Valid(WrappingMode::MirroredRepeat) => ImageAddressMode::MirrorRepeat,
            Checked::Valid(WrappingMode::ClampToEdge) => ImageAddressMode::ClampToEdge,
            Checked::Invalid => {
                warn(what);
                ImageAddressMode::Repeat
            }
        };
        let (nearest, linear) = (ImageFilterMode::Nearest, ImageFilterMode::Linear);
        let mag_filter = match s.mag_filter {
            None => linear,
            Some(Checked::Valid(MagFilter::Nearest)) => nearest,
            Some(Checked::Valid(MagFilter::Linear)) => linear,
            Some(Checked::Invalid) => {
                warn("magFilter");
                linear
            }
        };
        let (min_filter, mipmap_filter) = match s.min_filter {
            None => (linear, Some(linear)),
            Some(Checked::Valid(f)) => match f {
                MinFilter::Nearest => (nearest, None),
                MinFilter::Linear => (linear, None),
                MinFilter::NearestMipmapNearest => (nearest, Some(nearest)),
                MinFilter::LinearMipmapNearest => (linear, Some(nearest)),
                MinFilter::NearestMipmapLinear => (nearest, Some(linear)),
                MinFilter::LinearMipmapLinear => (linear, Some(linear)),
            },
            Some(Checked::Invalid) => {
                warn("minFilter");
                (linear, Some(linear))
            }
        };
        TextureSampler {
            address_mode_u: address(&s.wrap_s, "wrapS"),
            address_mode_v: address(&s.wrap_t, "wrapT"),
            mag_filter,
            min_filter,
            mipmap_filter,
            anisotropy_clamp: TextureSampler::default().anisotropy_clamp,
        }
    }

    /// The pixels of image `image` (the source of texture `texture`), as sRGB colour or as
    /// linear data.
    fn texture_image(
        &mut self,
        image: usize,
        texture: usize,
        srgb: bool,
    ) -> Result<Arc<TextureData>, SceneError> {
        let what = format!("texture {texture}");
        self.lookup(&self.root.images, image, &what, "image")?;
        let data = self.image(image)?;
        if srgb {
            return Ok(data);
        }
        if let Some(t) = self.linear.get(&image) {
            return Ok(t.clone());
        }
        // The same pixels, sampled without the sRGB decode; counted in the decoded-bytes budget.
        let needed = self.used.image_bytes.saturating_add(mip_chain_bytes(data.width, data.height));
        if needed > self.options.max_image_bytes {
            let what = format!("image {image} as linear data (with the images decoded before it)");
            let (unit, limit) = ("bytes of decoded images", self.options.max_image_bytes);
            return Err(over_budget(self.path, what, needed, unit, limit, "max_image_bytes"));
        }
        self.used.image_bytes = needed;
        let linear = Arc::new(TextureData { srgb: false, ..(*data).clone() });
        self.linear.insert(image, linear.clone());
        Ok(linear)
    }

    /// Decodes image `index` (cached by index and by source), checking format, size and the
    /// decoded-bytes budget first.
    fn image(&mut self, index: usize) -> Result<Arc<TextureData>, SceneError> {
        if let Some(t) = self.textures.get(&index) {
            return Ok(t.clone());
        }
        let root: &'a gltf::json::Root = self.root;
        let img = &root.images[index]; // the caller checked the index
        let what = format!("image {index}");
        let unsupported = |format: String| SceneError::UnsupportedImage {
            path: self.path.to_owned(),
            image: index,
            format,
        };
        // Resolve the source (a file is opened and checked, not read).
        let (source, file) = match (&img.uri, img.buffer_view) {
            (Some(uri), _) if is_data_uri(uri) => (ImageSource::Data(uri.as_str()), None),
            (Some(uri), _) => match resolve_uri(self.path, &self.base_dir, self.files, &what, uri)? {
                UriSource::File(file) => (ImageSource::File(file.path.clone()), Some(file)),
                // A fetched file, keyed by its URI as a `data:` URI is.
                UriSource::Bytes { .. } => (ImageSource::Data(uri.as_str()), None),
            },
            (None, Some(view)) => (ImageSource::View(view.value()), None),
            (None, None) => {
                return Err(SceneError::ImageDecode {
                    path: self.path.to_owned(),
                    image: index,
                    message: "has neither a uri nor a bufferView".into(),
                });
            }
        };
        // The media type of a `data:` URI wins over `mimeType`; checked for every entry.
        let mut mime = img.mime_type.as_ref().map(|m| m.0.to_ascii_lowercase());
        if let ImageSource::Data(uri) = source {
            let media_type = data_media_type(uri);
            if !media_type.is_empty() {
                mime = Some(media_type);
            }
        }
        if let Some(mime) = &mime
            && !matches!(mime.as_str(), "image/png" | "image/jpeg" | "image/jpg")
        {
            return Err(unsupported(format!("MIME type {mime}")));
        }
        if let Some(t) = self.images.get(&source) {
            let t = t.clone();
            self.textures.insert(index, t.clone());
            return Ok(t);
        }
        let (bytes, label): (Cow<'_, [u8]>, String) = match (&source, file) {
            (_, Some(file)) => {
                if file.size > MAX_IMAGE_FILE_BYTES {
                    return Err(SceneError::ReferencedFileTooLarge {
                        path: self.path.to_owned(),
                        what,
                        file: file.path,
                        size: file.size,
                        limit: MAX_IMAGE_FILE_BYTES,
                    });
                }
                let label = file.path.display().to_string();
                (Cow::Owned(file.read_prefix(self.path, &what, MAX_IMAGE_FILE_BYTES)?), label)
            }
            (ImageSource::View(view), None) => {
                (Cow::Borrowed(self.view_bytes(*view, &what)?), format!("{} image {index}", self.file_name()))
            }
            (_, None) => {
                let uri = img.uri.as_deref().unwrap_or_default();
                let bytes = match resolve_uri(self.path, &self.base_dir, self.files, &what, uri)? {
                    UriSource::Bytes { bytes } => bytes,
                    UriSource::File(file) => file.read_prefix(self.path, &what, MAX_IMAGE_FILE_BYTES)?,
                };
                (Cow::Owned(bytes), format!("{} image {index}", self.file_name()))
            }
        };
        let format = match image::guess_format(&bytes) {
            Ok(f @ (ImageFormat::Png | ImageFormat::Jpeg)) => f,
            Ok(other) => return Err(unsupported(format!("{other:?} data"))),
            Err(_) => return Err(unsupported("unrecognised data".into())),
        };
        let data = self.decode(index, &bytes, format, label)?;
        drop(bytes);
        self.used.image_bytes += mip_chain_bytes(data.width, data.height);
        let data = Arc::new(data);
        self.textures.insert(index, data.clone());
        self.images.insert(source, data.clone());
        Ok(data)
    }

    /// Decodes PNG/JPEG bytes to sRGB RGBA8 (16-bit and grey images are converted).
    fn decode(
        &self,
        index: usize,
        bytes: &[u8],
        format: ImageFormat,
        label: String,
    ) -> Result<TextureData, SceneError> {
        let decode_err = |e: image::ImageError| SceneError::ImageDecode {
            path: self.path.to_owned(),
            image: index,
            message: e.to_string(),
        };
        let max = self.options.max_texture_size;
        let downscale = self.options.oversized_textures == OversizedTextures::Downscale;
        // The largest side decoded: the limit itself, or the largest source a downscale takes.
        let decoded_max = if downscale { max.max(MAX_DOWNSCALED_SOURCE) } else { max };
        let mut decoder =
            ImageReader::with_format(Cursor::new(bytes), format).into_decoder().map_err(decode_err)?;
        let (width, height) = decoder.dimensions();
        if width > decoded_max || height > decoded_max {
            return Err(SceneError::TextureTooLarge {
                path: self.path.to_owned(),
                image: index,
                width,
                height,
                max: decoded_max,
            });
        }
        if width == 0 || height == 0 {
            return Err(SceneError::ImageDecode {
                path: self.path.to_owned(),
                image: index,
                message: "image has zero size".into(),
            });
        }
        // Counted with the images decoded before it: what the decode holds at its peak, and
        // what stays (`DecodeCost`).
        let (kept_width, kept_height) =
            if width > max || height > max { downscaled_size(width, height, max) } else { (width, height) };
        let cost = DecodeCost {
            source: decoder.total_bytes(),
            converts: decoder.color_type() != image::ColorType::Rgba8,
            width,
            height,
            kept_width,
            kept_height,
        };
        let needed = self.used.image_bytes.saturating_add(cost.peak().max(cost.kept()));
        if needed > self.options.max_image_bytes {
            let what = format!("image {index} (with the images decoded before it)");
            let (unit, limit) = ("bytes of decoded images", self.options.max_image_bytes);
            return Err(over_budget(self.path, what, needed, unit, limit, "max_image_bytes"));
        }
        let mut limits = Limits::default();
        limits.max_image_width = Some(decoded_max);
        limits.max_image_height = Some(decoded_max);
        // Room for the decoded image at 16 bits per channel plus decoder scratch.
        limits.max_alloc = Some((width as u64 * height as u64 * 8 * 2).max(512 << 20));
        decoder.set_limits(limits).map_err(decode_err)?;
        let mut rgba = image::DynamicImage::from_decoder(decoder).map_err(decode_err)?.into_rgba8();
        if (kept_width, kept_height) != (width, height) {
            // Only with OversizedTextures::Downscale: the larger side becomes `max`.
            let (w, h) = (kept_width, kept_height);
            tracing::info!(
                "{}: image {index} is {width}x{height}, downscaled to {w}x{h}",
                self.path.display()
            );
            rgba = image::imageops::resize(&rgba, w, h, image::imageops::FilterType::Triangle);
        }
        let (width, height) = rgba.dimensions();
        Ok(TextureData { label, width, height, rgba8: rgba.into_raw(), srgb: true })
    }
}

/// `width` × `height` scaled so that the larger side becomes `max` (each side at least 1).
fn downscaled_size(width: u32, height: u32, max: u32) -> (u32, u32) {
    let scale = max as f64 / width.max(height) as f64;
    let w = ((width as f64 * scale).round() as u32).clamp(1, max);
    let h = ((height as f64 * scale).round() as u32).clamp(1, max);
    (w, h)
}

/// Bytes an RGBA8 image of `width` × `height` takes with its whole mip chain, as the renderer
/// builds it at upload (each level half the size of the one before, down to 1 × 1).
pub(crate) fn mip_chain_bytes(width: u32, height: u32) -> u64 {
    let (mut w, mut h, mut total) = (width.max(1) as u64, height.max(1) as u64, 0u64);
    loop {
        total = total.saturating_add(w.saturating_mul(h).saturating_mul(4));
        if w == 1 && h == 1 {
            return total;
        }
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
}

/// The memory one image decode takes, counted in `LoadOptions::max_image_bytes` before it runs.
struct DecodeCost {
    /// Bytes of the image in the source's own pixel format (16-bit RGBA: 8 a pixel).
    source: u64,
    /// Whether the decoded image is converted to RGBA8 (a second copy while both are held).
    converts: bool,
    /// Source size.
    width: u32,
    height: u32,
    /// Size kept (after a downscale).
    kept_width: u32,
    kept_height: u32,
}

impl DecodeCost {
    /// Most bytes held at once while decoding: the source-format image with its RGBA8 copy,
    /// then the RGBA8 image with its downscaled copy.
    fn peak(&self) -> u64 {
        let rgba = self.width as u64 * self.height as u64 * 4;
        let converting = self.source.saturating_add(if self.converts { rgba } else { 0 });
        let downscaled = (self.kept_width, self.kept_height) != (self.width, self.height);
        let resizing =
            if downscaled { rgba + self.kept_width as u64 * self.kept_height as u64 * 4 } else { 0 };
        converting.max(resizing)
    }

    /// Bytes that stay once decoded: the RGBA8 image with its mip chain.
    fn kept(&self) -> u64 {
        mip_chain_bytes(self.kept_width, self.kept_height)
    }
}

#[cfg(test)]
mod decode_cost_tests {
    use super::*;

    #[test]
    fn a_16_bit_source_costs_its_own_bytes_and_the_rgba8_copy() {
        let cost =
            DecodeCost { source: 8 * 64, converts: true, width: 8, height: 8, kept_width: 8, kept_height: 8 };
        assert_eq!(cost.peak(), 8 * 64 + 4 * 64);
        assert_eq!(cost.kept(), 4 * (64 + 16 + 4 + 1));
        let rgba8 = DecodeCost { source: 4 * 64, converts: false, ..cost };
        assert_eq!(rgba8.peak(), 4 * 64);
    }

    #[test]
    fn mip_chains_of_odd_and_flat_images_end_at_one_pixel() {
        assert_eq!(mip_chain_bytes(1, 1), 4);
        assert_eq!(mip_chain_bytes(4, 1), 4 * (4 + 2 + 1));
        assert_eq!(mip_chain_bytes(3, 5), 4 * (15 + 2 + 1));
        assert!(mip_chain_bytes(u32::MAX, u32::MAX) > 0);
    }
}
