//! glTF materials and their base-colour images.
//!
//! Images are decoded once each (cached by image index) to sRGB RGBA8. Dimensions are read
//! from the image header and checked against `LoadOptions::max_texture_size` and the
//! `LoadOptions::max_image_bytes` budget before any pixel is decoded, so a tiny file that
//! declares a huge image costs nothing.

use super::uri::{UriSource, resolve_uri};
use super::{Ctx, over_budget};
use crate::SceneError;
use glam::Vec4;
use image::{ImageDecoder, ImageFormat, ImageReader, Limits};
use manylight_core::{MaterialData, TextureData};
use std::io::Cursor;
use std::sync::Arc;

/// Largest image file (in bytes) read from a URI; larger files are refused before reading.
const MAX_IMAGE_FILE_BYTES: u64 = 256 << 20;

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

impl Ctx<'_> {
    /// Converts material `index` (its base colour, base-colour texture and roughness).
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
                if info.tex_coord != 0 {
                    tracing::warn!(
                        file = %self.path.display(),
                        material = index,
                        "baseColorTexture uses TEXCOORD_{}, only TEXCOORD_0 is loaded",
                        info.tex_coord
                    );
                }
                let what = format!("material {index} baseColorTexture");
                let tex = self.lookup(&root.textures, info.index.value(), &what, "texture")?;
                let image = tex.source.value();
                let what = format!("texture {}", info.index.value());
                self.lookup(&root.images, image, &what, "image")?;
                Some(self.image(image)?)
            }
            None => None,
        };
        let (shininess, specular) = blinn_phong_from_pbr(pbr.roughness_factor.0, pbr.metallic_factor.0);
        Ok(MaterialData {
            label: m.name.clone().unwrap_or_else(|| format!("material {index}")),
            base_color: base,
            base_color_texture: texture,
            shading: None,
            shininess,
            specular,
        })
    }

    /// Decodes image `index` (cached), checking format and size first.
    fn image(&mut self, index: usize) -> Result<Arc<TextureData>, SceneError> {
        if let Some(t) = self.textures.get(&index) {
            return Ok(t.clone());
        }
        let root = self.root;
        let img = &root.images[index]; // the caller checked the index
        let what = format!("image {index}");
        let unsupported = |format: String| SceneError::UnsupportedImage {
            path: self.path.to_owned(),
            image: index,
            format,
        };
        let mut mime = img.mime_type.as_ref().map(|m| m.0.to_ascii_lowercase());
        let (bytes, label) = match (&img.uri, img.buffer_view) {
            (Some(uri), _) => match resolve_uri(self.path, &self.base_dir, &what, uri)? {
                UriSource::Data { bytes, media_type } => {
                    if !media_type.is_empty() {
                        mime = Some(media_type);
                    }
                    (bytes, format!("{} image {index}", self.file_name()))
                }
                UriSource::File(file) => {
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
                    (file.read_prefix(self.path, &what, MAX_IMAGE_FILE_BYTES)?, label)
                }
            },
            (None, Some(view)) => {
                let bytes = self.view_bytes(view.value(), &what)?.to_vec();
                (bytes, format!("{} image {index}", self.file_name()))
            }
            (None, None) => {
                return Err(SceneError::ImageDecode {
                    path: self.path.to_owned(),
                    image: index,
                    message: "has neither a uri nor a bufferView".into(),
                });
            }
        };
        if let Some(mime) = &mime
            && !matches!(mime.as_str(), "image/png" | "image/jpeg" | "image/jpg")
        {
            return Err(unsupported(format!("MIME type {mime}")));
        }
        let format = match image::guess_format(&bytes) {
            Ok(f @ (ImageFormat::Png | ImageFormat::Jpeg)) => f,
            Ok(other) => return Err(unsupported(format!("{other:?} data"))),
            Err(_) => return Err(unsupported("unrecognised data".into())),
        };
        let data = self.decode(index, &bytes, format, label)?;
        self.used.image_bytes += data.rgba8.len() as u64;
        let data = Arc::new(data);
        self.textures.insert(index, data.clone());
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
        let mut decoder =
            ImageReader::with_format(Cursor::new(bytes), format).into_decoder().map_err(decode_err)?;
        let (width, height) = decoder.dimensions();
        if width > max || height > max {
            return Err(SceneError::TextureTooLarge {
                path: self.path.to_owned(),
                image: index,
                width,
                height,
                max,
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
        limits.max_image_width = Some(max);
        limits.max_image_height = Some(max);
        // Room for the decoded image at 16 bits per channel plus decoder scratch.
        limits.max_alloc = Some((width as u64 * height as u64 * 8 * 2).max(512 << 20));
        decoder.set_limits(limits).map_err(decode_err)?;
        let rgba = image::DynamicImage::from_decoder(decoder).map_err(decode_err)?.into_rgba8();
        Ok(TextureData { label, width, height, rgba8: rgba.into_raw(), srgb: true })
    }
}
