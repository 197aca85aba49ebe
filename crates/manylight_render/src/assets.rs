//! Meshes, materials and textures on the GPU: uploaded once per distinct `Arc` on first use,
//! kept while instances use them and freed [`KEEP_FRAMES`] frames after the last one; the
//! material bind group layout and the samplers the materials name.

use crate::bindings::Binding;
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::{GpuMaterial, GpuTextureUv, SHADING_GLOBAL};
use crate::layouts::{GroupLayout, MATERIAL_GROUP};
use crate::shaders::ShaderDefs;
use manylight_core::{
    ImageAddressMode, ImageFilterMode, MaterialData, MeshData, TextureData, TextureSampler, Vertex,
};
use std::collections::HashMap;
use std::sync::Arc;

/// Frames a mesh/material/texture stays on the GPU after its last use.
pub const KEEP_FRAMES: u64 = 60;

/// A mesh on the GPU.
pub struct GpuMesh {
    _source: Arc<MeshData>,
    /// Interleaved [`Vertex`] buffer.
    pub vertices: wgpu::Buffer,
    /// u32 index buffer.
    pub indices: wgpu::Buffer,
    /// Number of indices.
    pub index_count: u32,
    /// Upload order (draws sort by it: the same scene draws in the same order on every run).
    pub order: u64,
    /// Centre of the mesh's bounds (local space).
    pub center: glam::Vec3,
    /// The mesh's bounds (local space).
    pub bounds: manylight_core::Aabb,
    last_used: u64,
}

struct CachedTexture {
    _source: Arc<TextureData>,
    view: wgpu::TextureView,
    last_used: u64,
}

/// A material's bind group (group 1 of mesh pipelines).
pub struct GpuMaterialBinding {
    _source: Arc<MaterialData>,
    /// The bind group.
    pub bind_group: wgpu::BindGroup,
    /// Upload order (see [`GpuMesh::order`]).
    pub order: u64,
    last_used: u64,
}

/// The scene's meshes, materials, textures and samplers on the GPU.
pub struct SceneAssets {
    /// Layout of group 1 ([`MATERIAL_GROUP`]).
    pub material_layout: GroupLayout,
    meshes: HashMap<usize, GpuMesh>,
    materials: HashMap<usize, GpuMaterialBinding>,
    textures: HashMap<usize, CachedTexture>,
    white: wgpu::TextureView,
    samplers: HashMap<TextureSampler, wgpu::Sampler>,
    /// The adapter filters anisotropically (`DownlevelFlags::ANISOTROPIC_FILTERING`).
    anisotropic: bool,
    frame: u64,
    max_texture_size: u32,
    uploads: u64,
}

impl SceneAssets {
    /// The material layout and empty caches.
    pub fn new(gpu: &GpuContext) -> SceneAssets {
        let device = &gpu.device;
        let material_layout = MATERIAL_GROUP.create_layout(device, ShaderDefs::default());
        let white = upload_texture(
            gpu,
            &TextureData { label: "white".into(), width: 1, height: 1, rgba8: vec![255; 4], srgb: true },
        );
        let anisotropic = gpu
            .adapter
            .get_downlevel_capabilities()
            .flags
            .contains(wgpu::DownlevelFlags::ANISOTROPIC_FILTERING);
        SceneAssets {
            material_layout,
            meshes: HashMap::new(),
            materials: HashMap::new(),
            textures: HashMap::new(),
            white,
            samplers: HashMap::new(),
            anisotropic,
            frame: 0,
            max_texture_size: gpu.max_texture_size(),
            uploads: 0,
        }
    }

    /// Starts a frame: what it uses is stamped with it.
    pub fn begin_frame(&mut self) {
        self.frame += 1;
    }

    /// Frees what no instance used for [`KEEP_FRAMES`] frames.
    pub fn evict_unused(&mut self) {
        let frame = self.frame;
        self.meshes.retain(|_, m| frame - m.last_used <= KEEP_FRAMES);
        self.materials.retain(|_, m| frame - m.last_used <= KEEP_FRAMES);
        self.textures.retain(|_, t| frame - t.last_used <= KEEP_FRAMES);
    }

    /// The mesh's GPU buffers, uploaded on first use; refused, naming the limit, when a buffer
    /// would exceed the device's `max_buffer_size`.
    pub fn mesh_entry(
        &mut self,
        gpu: &GpuContext,
        mesh: &Arc<MeshData>,
    ) -> Result<(usize, u64, glam::Vec3, manylight_core::Aabb), RenderError> {
        let k = key(mesh);
        let frame = self.frame;
        if !self.meshes.contains_key(&k) {
            let limit = gpu.device.limits().max_buffer_size;
            let vertex_bytes = std::mem::size_of_val(mesh.vertices.as_slice()) as u64;
            let index_bytes = std::mem::size_of_val(mesh.indices.as_slice()) as u64;
            for (what, bytes) in [("vertex", vertex_bytes), ("index", index_bytes)] {
                if bytes > limit {
                    return Err(RenderError::BufferTooLarge {
                        label: format!("{}: {what} buffer", mesh.label),
                        bytes,
                        limit,
                        limit_name: "max_buffer_size",
                    });
                }
            }
        }
        let uploads = &mut self.uploads;
        let entry = self.meshes.entry(k).or_insert_with(|| {
            *uploads += 1;
            GpuMesh {
                _source: mesh.clone(),
                vertices: gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&mesh.label),
                    contents: bytemuck::cast_slice::<Vertex, u8>(&mesh.vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
                indices: gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&mesh.label),
                    contents: bytemuck::cast_slice(&mesh.indices),
                    usage: wgpu::BufferUsages::INDEX,
                }),
                index_count: mesh.indices.len() as u32,
                order: *uploads,
                center: {
                    let b = mesh.bounds();
                    let c = (b.min + b.max) * 0.5;
                    if c.is_finite() { c } else { glam::Vec3::ZERO }
                },
                bounds: mesh.bounds(),
                last_used: frame,
            }
        });
        entry.last_used = frame;
        Ok((k, entry.order, entry.center, entry.bounds))
    }

    /// The material's bind group, made on first use (its textures uploaded); its key and upload
    /// order.
    pub fn material_entry(
        &mut self,
        gpu: &GpuContext,
        material: &Arc<MaterialData>,
    ) -> Result<(usize, u64), RenderError> {
        let k = key(material);
        let frame = self.frame;
        if let Some(m) = self.materials.get_mut(&k) {
            m.last_used = frame;
            for t in material.textures() {
                if let Some(t) = self.textures.get_mut(&key(&t.image)) {
                    t.last_used = frame;
                }
            }
            return Ok((k, m.order));
        }
        let slots = material.texture_slots();
        let mut views = Vec::with_capacity(slots.len());
        let mut samplers = Vec::with_capacity(slots.len());
        for slot in slots {
            views.push(self.texture_view(gpu, slot.map(|t| &t.image))?);
            samplers.push(self.sampler(gpu, slot.map_or(UNUSED_SLOT_SAMPLER, |t| t.sampler)));
        }
        let finite_or = |v: f32, default: f32| if v.is_finite() { v } else { default };
        let uniform = GpuMaterial {
            base_color: material.base_color_linear(),
            shininess: material.shininess.clamp(1.0, 4096.0),
            specular: material.specular.max(0.0),
            shading_model: material.shading.map_or(SHADING_GLOBAL, |s| s.gpu_id()),
            has_texture: material.base_color_texture.is_some() as u32,
            metallic: if material.metallic.is_finite() { material.metallic.clamp(0.0, 1.0) } else { 0.0 },
            roughness: if material.roughness.is_finite() { material.roughness.clamp(0.0, 1.0) } else { 1.0 },
            has_metallic_roughness_texture: material.metallic_roughness_texture.is_some() as u32,
            normal_scale: finite_or(material.normal_scale, 1.0),
            emissive: if material.emissive_rgb().is_finite() {
                material.emissive_rgb().max(glam::Vec3::ZERO)
            } else {
                glam::Vec3::ZERO
            },
            occlusion_strength: finite_or(material.occlusion_strength, 1.0).clamp(0.0, 1.0),
            has_normal_texture: material.normal_texture.is_some() as u32,
            has_occlusion_texture: material.occlusion_texture.is_some() as u32,
            has_emissive_texture: material.emissive_texture.is_some() as u32,
            alpha_cutoff: material.alpha_mode.cutoff().unwrap_or(0.0),
            texture_uv: slots.map(GpuTextureUv::of),
        };
        let buffer = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(&material.label),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        // The uniform, then each texture (base colour, metallic-roughness, normal map,
        // occlusion, emissive) followed by its sampler.
        let mut resources = vec![Binding::Buffer(&buffer)];
        for (view, sampler) in views.iter().zip(&samplers) {
            resources.extend([Binding::Texture(view), Binding::Sampler(sampler)]);
        }
        let bind_group = self.material_layout.create_bind_group(gpu, &resources);
        self.uploads += 1;
        let order = self.uploads;
        self.materials
            .insert(k, GpuMaterialBinding { _source: material.clone(), bind_group, order, last_used: frame });
        Ok((k, order))
    }

    /// The sampler for `s`, created on first use (a handful per scene: glTF files name few
    /// distinct samplers).
    fn sampler(&mut self, gpu: &GpuContext, s: TextureSampler) -> wgpu::Sampler {
        let anisotropy = if s.allows_anisotropy() && self.anisotropic {
            s.anisotropy_clamp.min(manylight_core::material::MAX_ANISOTROPY)
        } else {
            1
        };
        self.samplers
            .entry(s)
            .or_insert_with(|| {
                let address = |m: ImageAddressMode| match m {
                    ImageAddressMode::Repeat => wgpu::AddressMode::Repeat,
                    ImageAddressMode::MirrorRepeat => wgpu::AddressMode::MirrorRepeat,
                    ImageAddressMode::ClampToEdge => wgpu::AddressMode::ClampToEdge,
                };
                let filter = |f: ImageFilterMode| match f {
                    ImageFilterMode::Nearest => wgpu::FilterMode::Nearest,
                    ImageFilterMode::Linear => wgpu::FilterMode::Linear,
                };
                let mipmap_filter = match s.mipmap_filter {
                    Some(ImageFilterMode::Linear) => wgpu::MipmapFilterMode::Linear,
                    _ => wgpu::MipmapFilterMode::Nearest,
                };
                gpu.device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("material_sampler"),
                    address_mode_u: address(s.address_mode_u),
                    address_mode_v: address(s.address_mode_v),
                    address_mode_w: wgpu::AddressMode::Repeat,
                    mag_filter: filter(s.mag_filter),
                    min_filter: filter(s.min_filter),
                    mipmap_filter,
                    // Without mipmaps only the full-size level is sampled.
                    lod_max_clamp: if s.mipmap_filter.is_some() { 32.0 } else { 0.0 },
                    anisotropy_clamp: anisotropy,
                    ..Default::default()
                })
            })
            .clone()
    }

    /// The view of `texture`, uploaded on first use (white when there is none); refused,
    /// naming the limit, when it exceeds the device's largest texture.
    fn texture_view(
        &mut self,
        gpu: &GpuContext,
        texture: Option<&Arc<TextureData>>,
    ) -> Result<wgpu::TextureView, RenderError> {
        let Some(tex) = texture else { return Ok(self.white.clone()) };
        if tex.width > self.max_texture_size || tex.height > self.max_texture_size {
            return Err(RenderError::TextureTooLarge {
                label: tex.label.clone(),
                width: tex.width,
                height: tex.height,
                limit: self.max_texture_size,
            });
        }
        let frame = self.frame;
        let entry = self.textures.entry(key(tex)).or_insert_with(|| CachedTexture {
            _source: tex.clone(),
            view: upload_texture(gpu, tex),
            last_used: frame,
        });
        entry.last_used = frame;
        Ok(entry.view.clone())
    }

    /// The GPU mesh of a draw.
    pub fn mesh(&self, key: usize) -> Option<&GpuMesh> {
        self.meshes.get(&key)
    }

    /// The material bind group of a draw.
    pub fn material(&self, key: usize) -> Option<&GpuMaterialBinding> {
        self.materials.get(&key)
    }

    /// Meshes, materials and textures resident on the GPU.
    pub fn resident_counts(&self) -> (usize, usize, usize) {
        (self.meshes.len(), self.materials.len(), self.textures.len())
    }
}

fn key<T>(a: &Arc<T>) -> usize {
    Arc::as_ptr(a) as *const u8 as usize
}

/// The sampler of an empty texture slot (its 1×1 white texture): the cheapest there is. On
/// lavapipe an anisotropic sampler costs its full price even on a 1×1 texture.
const UNUSED_SLOT_SAMPLER: TextureSampler = TextureSampler {
    address_mode_u: ImageAddressMode::ClampToEdge,
    address_mode_v: ImageAddressMode::ClampToEdge,
    mag_filter: ImageFilterMode::Nearest,
    min_filter: ImageFilterMode::Nearest,
    mipmap_filter: None,
    anisotropy_clamp: 1,
};

/// Uploads an RGBA8 texture with a full mip chain (box-filtered on the CPU).
fn upload_texture(gpu: &GpuContext, tex: &TextureData) -> wgpu::TextureView {
    let format = if tex.srgb { wgpu::TextureFormat::Rgba8UnormSrgb } else { wgpu::TextureFormat::Rgba8Unorm };
    let levels = 32 - tex.width.max(tex.height).max(1).leading_zeros();
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(&tex.label),
        size: wgpu::Extent3d { width: tex.width, height: tex.height, depth_or_array_layers: 1 },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let (mut w, mut h) = (tex.width, tex.height);
    let mut level: std::borrow::Cow<[u8]> = std::borrow::Cow::Borrowed(&tex.rgba8);
    for mip in 0..levels {
        gpu.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: mip,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &level,
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * w), rows_per_image: Some(h) },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        if mip + 1 < levels {
            let next = downsample(&level, w, h, tex.srgb);
            w = (w / 2).max(1);
            h = (h / 2).max(1);
            level = std::borrow::Cow::Owned(next);
        }
    }
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

/// 2×2 box filter (in linear light for sRGB data).
fn downsample(src: &[u8], w: u32, h: u32, srgb: bool) -> Vec<u8> {
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let to_lin = |v: u8| {
        let c = v as f32 / 255.0;
        if srgb { if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) } } else { c }
    };
    let from_lin = |c: f32| {
        let v =
            if srgb { if c <= 0.0031308 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 } } else { c };
        (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
    };
    let mut out = vec![0u8; (nw * nh * 4) as usize];
    for y in 0..nh {
        for x in 0..nw {
            for c in 0..4 {
                let mut sum = 0.0;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let sx = (2 * x + dx).min(w - 1);
                    let sy = (2 * y + dy).min(h - 1);
                    let v = src[((sy * w + sx) * 4 + c) as usize];
                    sum += if c == 3 { v as f32 / 255.0 } else { to_lin(v) };
                }
                let avg = sum / 4.0;
                out[((y * nw + x) * 4 + c) as usize] =
                    if c == 3 { (avg.clamp(0.0, 1.0) * 255.0 + 0.5) as u8 } else { from_lin(avg) };
            }
        }
    }
    out
}
