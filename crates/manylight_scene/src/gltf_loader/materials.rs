//! glTF materials and their images.
//!
//! Images are decoded to sRGB RGBA8 once per distinct source (the same resolved file, the same
//! `data:` URI or the same buffer view), however many `images` entries name it. Dimensions
//! are read from the image header and checked against `LoadOptions::max_texture_size` and
//! the `LoadOptions::max_image_bytes` budget before any pixel is decoded, so a tiny file that
//! declares a huge image, or names one image many times, costs nothing.
//!
//! Colour textures (base colour, emissive) use the sRGB decode; data textures
//! (metallic-roughness, normal, occlusion) use a linear copy of the same pixels, made once per
//! image and also counted against `max_image_bytes`.

use super::uri::{UriSource, is_data_uri, resolve_uri, split_data_uri};
use super::{Ctx, MAX_DOWNSCALED_SOURCE, OversizedTextures, over_budget};
use crate::SceneError;
use glam::{Vec3, Vec4};
use gltf::json::validation::Checked;
use image::{ImageDecoder, ImageFormat, ImageReader, Limits};
use manylight_core::{AlphaMode, MaterialData, TextureData};
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
    /// A `data:` URI, by its text.
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

/// The `KHR_materials_emissive_strength` `emissiveStrength` of every material of glTF JSON
/// `json` (already parsed by `gltf`), by material index; empty when the file does not mention
/// the extension. A missing, non-numeric, negative or non-finite strength is 1 (with a warning
/// for the last three).
///
/// The `gltf` crate drops material extensions unless its `KHR_materials_emissive_strength`
/// feature is on, so they are read from the text: each level is parsed into a map of raw
/// (unparsed) values, so the rest of the document is only scanned, never built.
pub(super) fn emissive_strengths(path: &Path, json: &[u8]) -> Vec<f32> {
    use serde_json::value::RawValue;
    type RawMap<'j> = HashMap<String, &'j RawValue>;
    if !json.windows(EMISSIVE_STRENGTH.len()).any(|w| w == EMISSIVE_STRENGTH.as_bytes()) {
        return Vec::new();
    }
    let materials = serde_json::from_slice::<RawMap<'_>>(json).ok().and_then(|top| {
        let list = top.get("materials")?;
        serde_json::from_str::<Vec<&RawValue>>(list.get()).ok()
    });
    let Some(materials) = materials else {
        tracing::warn!(file = %path.display(), "could not read {EMISSIVE_STRENGTH}, ignored");
        return Vec::new();
    };
    let strength = |(index, m): (usize, &&RawValue)| -> f32 {
        let ext = serde_json::from_str::<RawMap<'_>>(m.get()).ok().and_then(|m| {
            let exts = serde_json::from_str::<RawMap<'_>>(m.get("extensions")?.get()).ok()?;
            Some(serde_json::from_str::<serde_json::Map<String, Value>>(exts.get(EMISSIVE_STRENGTH)?.get()))
        });
        let value = match ext {
            None => return 1.0,
            Some(Ok(ext)) => match ext.get("emissiveStrength") {
                None => return 1.0,
                Some(v) => v.as_f64().map(|v| v as f32),
            },
            Some(Err(_)) => None,
        };
        match value {
            Some(v) if v.is_finite() && v >= 0.0 => v,
            _ => {
                tracing::warn!(
                    file = %path.display(), material = index,
                    "{EMISSIVE_STRENGTH}: emissiveStrength is not a finite non-negative number, using 1"
                );
                1.0
            }
        }
    };
    materials.iter().enumerate().map(strength).collect()
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
        let texture = match &pbr.base_color_texture {
            Some(info) => {
                Some(self.texture(index, "baseColorTexture", info.index.value(), info.tex_coord, true)?)
            }
            None => None,
        };
        let metallic_roughness_texture = match &pbr.metallic_roughness_texture {
            Some(info) => {
                let (i, uv) = (info.index.value(), info.tex_coord);
                Some(self.texture(index, "metallicRoughnessTexture", i, uv, false)?)
            }
            None => None,
        };
        let (normal_texture, normal_scale) = match &m.normal_texture {
            Some(info) => {
                let t = self.texture(index, "normalTexture", info.index.value(), info.tex_coord, false)?;
                (Some(t), self.finite(info.scale, index, "normalTexture.scale", 1.0))
            }
            None => (None, 1.0),
        };
        let (occlusion_texture, occlusion_strength) = match &m.occlusion_texture {
            Some(info) => {
                let t = self.texture(index, "occlusionTexture", info.index.value(), info.tex_coord, false)?;
                let strength = self.finite(info.strength.0, index, "occlusionTexture.strength", 1.0);
                (Some(t), strength.clamp(0.0, 1.0))
            }
            None => (None, 1.0),
        };
        let emissive_texture = match &m.emissive_texture {
            Some(info) => {
                Some(self.texture(index, "emissiveTexture", info.index.value(), info.tex_coord, true)?)
            }
            None => None,
        };
        let mut emissive = Vec3::from_array(m.emissive_factor.0);
        if !emissive.is_finite() {
            tracing::warn!(file = %self.path.display(), material = index, "non-finite emissiveFactor, using black");
            emissive = Vec3::ZERO;
        }
        let strength = self.emissive_strengths.get(index).copied().unwrap_or(1.0);
        // Clamped after the product, which may overflow to infinity.
        let emissive = (emissive.max(Vec3::ZERO) * strength).min(Vec3::splat(f32::MAX));
        let factor = |v: f32, name: &str, default: f32| self.finite(v, index, name, default).clamp(0.0, 1.0);
        let metallic = factor(pbr.metallic_factor.0, "metallicFactor", 1.0);
        let roughness = factor(pbr.roughness_factor.0, "roughnessFactor", 1.0);
        let (shininess, specular) = blinn_phong_from_pbr(roughness, metallic);
        let alpha_mode = self.alpha_mode(index);
        Ok(MaterialData {
            label: m.name.clone().unwrap_or_else(|| format!("material {index}")),
            base_color: base,
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
            emissive,
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

    /// The `alphaMode` (and `alphaCutoff`) of material `index`. `BLEND` is kept but drawn
    /// opaque for now, which is logged once per file.
    fn alpha_mode(&mut self, index: usize) -> AlphaMode {
        let m = &self.root.materials[index];
        match m.alpha_mode {
            Checked::Valid(gltf::json::material::AlphaMode::Opaque) => AlphaMode::Opaque,
            Checked::Valid(gltf::json::material::AlphaMode::Mask) => {
                let cutoff = m.alpha_cutoff.map_or(AlphaMode::DEFAULT_CUTOFF, |c| c.0);
                let cutoff = self.finite(cutoff, index, "alphaCutoff", AlphaMode::DEFAULT_CUTOFF);
                AlphaMode::Mask(cutoff.max(0.0))
            }
            Checked::Valid(gltf::json::material::AlphaMode::Blend) => {
                if !std::mem::replace(&mut self.warned_blend, true) {
                    tracing::warn!(
                        file = %self.path.display(), material = index,
                        "alphaMode BLEND is drawn opaque for now (no transparent pass yet)"
                    );
                }
                AlphaMode::Blend
            }
            Checked::Invalid => {
                tracing::warn!(file = %self.path.display(), material = index, "unknown alphaMode, using OPAQUE");
                AlphaMode::Opaque
            }
        }
    }

    /// The image of texture `texture` used by material `material` through `TEXCOORD_<tex_coord>`
    /// (`slot` names the material's property in errors), as sRGB colour or as linear data.
    fn texture(
        &mut self,
        material: usize,
        slot: &str,
        texture: usize,
        tex_coord: u32,
        srgb: bool,
    ) -> Result<Arc<TextureData>, SceneError> {
        let root = self.root;
        if tex_coord != 0 {
            tracing::warn!(
                file = %self.path.display(),
                material,
                "{slot} uses TEXCOORD_{tex_coord}, only TEXCOORD_0 is loaded",
            );
        }
        let what = format!("material {material} {slot}");
        let tex = self.lookup(&root.textures, texture, &what, "texture")?;
        let image = tex.source.value();
        let what = format!("texture {texture}");
        self.lookup(&root.images, image, &what, "image")?;
        let data = self.image(image)?;
        if srgb {
            return Ok(data);
        }
        if let Some(t) = self.linear.get(&image) {
            return Ok(t.clone());
        }
        // The same pixels, sampled without the sRGB decode; counted in the decoded-bytes budget.
        let needed = self.used.image_bytes.saturating_add(data.rgba8.len() as u64);
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
            (Some(uri), _) => match resolve_uri(self.path, &self.base_dir, &what, uri)? {
                UriSource::File(file) => (ImageSource::File(file.path.clone()), Some(file)),
                // `resolve_uri` decodes only `data:` URIs, handled above.
                UriSource::Data { .. } => (ImageSource::Data(uri.as_str()), None),
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
                let bytes = match resolve_uri(self.path, &self.base_dir, &what, uri)? {
                    UriSource::Data { bytes, .. } => bytes,
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
        self.used.image_bytes += data.rgba8.len() as u64;
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
        // Decoded as RGBA8; counted with the images decoded before it.
        let needed = self.used.image_bytes.saturating_add(width as u64 * height as u64 * 4);
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
        if width > max || height > max {
            // Only with OversizedTextures::Downscale: the larger side becomes `max`.
            let scale = max as f64 / width.max(height) as f64;
            let w = ((width as f64 * scale).round() as u32).clamp(1, max);
            let h = ((height as f64 * scale).round() as u32).clamp(1, max);
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
