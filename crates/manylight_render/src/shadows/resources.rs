//! The shadow atlas and the buffers of its pass, kept across frames, and a frame's preparation
//! in order ([`ShadowResources::prepare`]): requests, the atlas plan and the blocks, what each
//! map holds, which maps are drawn, then the upload.

use super::ShadowReport;
use super::cache::{CachedMap, MapState};
use super::frustum::view_frustums;
use super::gather::{MapInputs, MapWork, caster_bounds};
use super::plan::{AtlasPlan, atlas_limit, place_stably, plan_atlas};
use super::requests::{ShadowCaster, ShadowRequest};
use crate::atlas::BlockAllocator;
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::{
    GpuDirectionalShadow, GpuShadowDraw, GpuShadowFace, GpuShadowLight, MAX_DIRECTIONAL_LIGHTS,
    SHADOW_TILE_COLUMNS,
};
use crate::lights::viewed_directional_lights;
use crate::pool::GrowableBuffer;
use crate::resources::SceneResources;
use crate::snapshot::{ExtractedDirectionalLight, FrameSnapshot};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};

/// Depth format of the shadow atlas.
pub const SHADOW_ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A run of the shadow pass's draw instances that share a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowMeshDraws {
    /// Key into `SceneAssets::mesh`.
    pub mesh: usize,
    /// First instance (index into the draw buffer).
    pub first: u32,
    /// Instances.
    pub count: u32,
}

/// The shadow atlas and the buffers of its pass, kept across frames. Over 15 fields: the atlas,
/// the four buffers the shading and shadow passes bind, this frame's plan, report and the
/// flags the shadow pass reads, the device's capabilities, and the maps kept from frame to
/// frame; what a frame only builds in is its `ShadowScratch`.
pub struct ShadowResources {
    /// The atlas (created on the first frame with a casting light, grown when a frame needs a
    /// larger one, never shrunk).
    atlas: Option<wgpu::Texture>,
    atlas_view: Option<wgpu::TextureView>,
    /// The comparison sampler of the shading passes (linear: a 2×2 filter).
    pub sampler: wgpu::Sampler,
    /// [`GpuShadowLight`] per light of the light buffer.
    pub lights: GrowableBuffer,
    /// [`GpuDirectionalShadow`] per entry of the view's directional lights
    /// ([`MAX_DIRECTIONAL_LIGHTS`]; no cascade where a light casts none).
    pub directional: GrowableBuffer,
    /// [`GpuShadowFace`] per placed face.
    pub faces: GrowableBuffer,
    /// [`GpuShadowDraw`] per (instance, face) pair, grouped by mesh.
    pub draws: GrowableBuffer,
    /// The runs of `draws` by mesh, in the scene's draw order.
    pub mesh_draws: Vec<ShadowMeshDraws>,
    /// This frame's plan.
    pub plan: AtlasPlan,
    /// This frame's counters.
    pub report: ShadowReport,
    /// True when the frame has a shadow map to draw and read.
    pub active: bool,
    /// Bumped whenever the atlas or the light table is re-created (the view bind group follows).
    pub generation: u64,
    /// The device draws clip distances (`Features::CLIP_DISTANCES`); otherwise the shadow
    /// pass discards the fragments outside each face's tile.
    pub clip_distances: bool,
    /// The device clamps depth instead of clipping it (`Features::DEPTH_CLIP_CONTROL`): the
    /// shadow pass clamps, so a cascade's depth range is its slice's sphere alone.
    pub clamps_depth: bool,
    /// Some maps of the atlas are kept this frame: the pass loads the atlas and clears the
    /// tiles it draws, instead of clearing the whole atlas.
    pub clears_tiles: bool,
    /// Faces drawn this frame: the first `faces_drawn` of `faces`.
    pub faces_drawn: u32,
    /// Set when a frame has maps to draw, taken by the first view's shadow pass.
    pending_draw: AtomicBool,
    /// Where each light's block lies, kept from frame to frame.
    allocator: BlockAllocator<ShadowCaster>,
    /// The maps the atlas holds, by light.
    pub(super) cache: HashMap<ShadowCaster, CachedMap>,
    pub(super) next_cache: HashMap<ShadowCaster, CachedMap>,
    /// The largest atlas edge the device allows (or [`ShadowResources::limit_texture_size`]).
    max_texture: u32,
    /// What a frame builds its plan and uploads in.
    pub(super) scratch: ShadowScratch,
}

/// What a frame builds its shadow plan and uploads in: emptied and refilled each frame, kept
/// between frames so that a steady frame allocates nothing.
#[derive(Default)]
pub(super) struct ShadowScratch {
    /// The maps to draw, with their inputs.
    pub(super) work: Vec<MapWork>,
    /// The faces of `work`, packed.
    pub(super) work_faces: Vec<GpuShadowFace>,
    /// The (mesh, draw) pairs of `work`.
    pub(super) work_draws: Vec<(usize, GpuShadowDraw)>,
    /// The light table, packed.
    pub(super) gpu_lights: Vec<GpuShadowLight>,
    /// The directional lights' cascades, packed.
    pub(super) gpu_directional: Vec<GpuDirectionalShadow>,
    /// Every placed face, packed.
    pub(super) gpu_faces: Vec<GpuShadowFace>,
    /// The draws grouped by mesh.
    pub(super) by_mesh: Vec<(usize, Vec<GpuShadowDraw>)>,
    /// Which lights ask for a map, and how big.
    pub(super) requests: Vec<ShadowRequest>,
}

impl ShadowResources {
    /// Empty buffers and the sampler; no atlas until a light casts.
    pub fn new(gpu: &GpuContext) -> ShadowResources {
        let storage = wgpu::BufferUsages::STORAGE;
        ShadowResources {
            atlas: None,
            atlas_view: None,
            sampler: gpu.device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("shadow_sampler"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                // Reverse depth: lit where the point is at least as near as the stored caster.
                compare: Some(wgpu::CompareFunction::GreaterEqual),
                ..Default::default()
            }),
            lights: GrowableBuffer::new(
                gpu,
                "shadow_lights",
                storage,
                std::mem::size_of::<GpuShadowLight>() as u64,
            ),
            directional: GrowableBuffer::new(
                gpu,
                "shadow_directional",
                storage,
                std::mem::size_of::<GpuDirectionalShadow>() as u64 * u64::from(MAX_DIRECTIONAL_LIGHTS),
            ),
            faces: GrowableBuffer::new(
                gpu,
                "shadow_faces",
                storage,
                std::mem::size_of::<GpuShadowFace>() as u64,
            ),
            draws: GrowableBuffer::new(
                gpu,
                "shadow_draws",
                storage,
                std::mem::size_of::<GpuShadowDraw>() as u64,
            ),
            mesh_draws: Vec::new(),
            plan: AtlasPlan::default(),
            report: ShadowReport::default(),
            active: false,
            generation: 0,
            clip_distances: gpu.device.features().contains(wgpu::Features::CLIP_DISTANCES),
            clamps_depth: gpu.device.features().contains(wgpu::Features::DEPTH_CLIP_CONTROL),
            clears_tiles: false,
            faces_drawn: 0,
            pending_draw: AtomicBool::new(false),
            allocator: BlockAllocator::new(0, 1),
            cache: HashMap::new(),
            next_cache: HashMap::new(),
            max_texture: gpu.max_texture_size(),
            scratch: ShadowScratch {
                gpu_directional: vec![GpuDirectionalShadow::default(); MAX_DIRECTIONAL_LIGHTS as usize],
                ..ShadowScratch::default()
            },
        }
    }

    /// Caps the atlas at `texels` (rounded down to a power of two) as a device whose textures
    /// are that small would; the device's own limit still applies.
    pub fn limit_texture_size(&mut self, texels: u32) {
        self.max_texture = self.max_texture.min(texels.max(1));
    }

    /// The atlas texture, once a frame had a casting light.
    pub fn atlas(&self) -> Option<&wgpu::Texture> {
        self.atlas.as_ref()
    }

    /// The atlas's view, once a frame had a casting light.
    pub fn atlas_view(&self) -> Option<&wgpu::TextureView> {
        self.atlas_view.as_ref()
    }

    /// What group 0 binds for this frame's shadows; `None` when the frame draws none.
    pub fn bindings(&self) -> Option<crate::resources::ShadowBindings<'_>> {
        let atlas = self.atlas_view.as_ref().filter(|_| self.active)?;
        Some(crate::resources::ShadowBindings {
            atlas,
            sampler: &self.sampler,
            lights: self.lights.buffer(),
            directional: self.directional.buffer(),
            generation: self.generation,
        })
    }

    /// Plans the frame's atlas and uploads its faces, draws and light table (after
    /// [`SceneResources::prepare`], whose lights, instances and draws it reads).
    pub fn prepare(
        &mut self,
        gpu: &GpuContext,
        scene: &SceneResources,
        snapshot: &FrameSnapshot,
    ) -> Result<(), RenderError> {
        let settings = snapshot.settings.shadows;
        self.start_frame();
        if !snapshot.draws_shadow_maps() {
            self.plan = AtlasPlan::default();
            return Ok(());
        }
        let camera = snapshot.views.first().map(|v| (&v.camera, snapshot.viewport));
        let frustums = view_frustums(snapshot);
        self.request_point_maps(snapshot, camera, &frustums);
        // Directional lights, by their index in the view uniform (the first
        // MAX_DIRECTIONAL_LIGHTS valid ones).
        let directional: Vec<&ExtractedDirectionalLight> =
            viewed_directional_lights(&snapshot.directional_lights).map(|(_, l)| l).collect();
        let view = camera.map(|(c, size)| (c, size.x.max(1) as f32 / size.y.max(1) as f32));
        // The largest power of two the device's textures allow.
        let (max_atlas, limited) = atlas_limit(settings.atlas_size, self.max_texture);
        self.request_cascades(&settings, &directional, view.is_some(), max_atlas);
        // Each light's edge from the whole frame's needs, then its place: where it was while
        // its edge holds.
        let min_edge = settings.min_face_size.min(max_atlas / SHADOW_TILE_COLUMNS).max(1);
        let target = plan_atlas(&self.scratch.requests, max_atlas, min_edge);
        self.report.casting_lights = self.scratch.requests.len() as u32 + self.report.unseen_lights;
        self.report.atlas_limited_by_device = limited;
        if target.placements.is_empty() {
            self.report.dropped_lights = target.dropped;
            self.plan = target;
            return Ok(());
        }
        let atlas = self.place_maps(gpu, &target, min_edge);

        // The light table: every light of the buffer, edge 0 where it has no map.
        self.scratch.gpu_lights.clear();
        self.scratch.gpu_lights.resize(scene.lights.count.max(1) as usize, GpuShadowLight::default());
        let lights = &snapshot.lights;
        self.scratch.gpu_faces.clear();
        for list in &mut self.scratch.by_mesh {
            list.1.clear();
        }
        let opaque = self.opaque_draws(scene);
        let casters = caster_bounds(&opaque);
        self.scratch.gpu_directional.fill(GpuDirectionalShadow::default());
        let importance = self.scratch.requests.iter().map(|r| (r.caster, r.importance)).collect();
        let inputs =
            MapInputs { settings, atlas, lights, directional, view, frustums, opaque, casters, importance };

        let mut work = self.gather_work(&inputs);
        self.choose_redraws(&mut work, &settings);
        self.commit_maps(&work);
        self.clears_tiles = work.iter().any(|w| w.state != MapState::Draw);
        self.scratch.work = work;
        self.upload(gpu, scene, atlas)
    }

    /// Clears the last frame's counters and draws; forgets the maps of a frame whose views
    /// drew none.
    fn start_frame(&mut self) {
        // Maps planned for a frame whose views drew none (no view shaded lights) are not in
        // the atlas.
        if self.pending_draw.swap(false, Ordering::Relaxed) {
            self.cache.clear();
        }
        self.report = ShadowReport::default();
        self.active = false;
        self.clears_tiles = false;
        self.faces_drawn = 0;
        self.mesh_draws.clear();
    }

    /// Places `target`'s maps in the atlas (created or grown to its size first), each where it
    /// was while its edge holds ([`place_stably`]), as the frame's plan; returns the atlas
    /// texture's edge.
    fn place_maps(&mut self, gpu: &GpuContext, target: &AtlasPlan, min_edge: u32) -> u32 {
        self.ensure_atlas(gpu, target.atlas_size);
        let atlas = self.atlas.as_ref().map_or(target.atlas_size, |t| t.width());
        if !self.allocator.serves(atlas, min_edge) {
            self.allocator = BlockAllocator::new(atlas, min_edge);
        }
        self.plan = place_stably(&mut self.allocator, target, &self.scratch.requests);
        self.report.downgraded_lights = self.plan.downgraded;
        self.report.dropped_lights = self.plan.dropped;
        atlas
    }

    /// Groups the frame's pairs by mesh (meshes no longer drawn leave the list), uploads the
    /// shadow tables, faces and pairs, and marks the frame's maps for drawing in an `atlas`
    /// texels wide atlas.
    fn upload(&mut self, gpu: &GpuContext, scene: &SceneResources, atlas: u32) -> Result<(), RenderError> {
        self.scratch.by_mesh.retain(|(mesh, _)| scene.assets.mesh(*mesh).is_some());
        let mut all = Vec::new();
        for (mesh, list) in &self.scratch.by_mesh {
            if list.is_empty() {
                continue;
            }
            self.mesh_draws.push(ShadowMeshDraws {
                mesh: *mesh,
                first: all.len() as u32,
                count: list.len() as u32,
            });
            all.extend_from_slice(list);
        }
        let mut grew = self.lights.write(gpu, bytemuck::cast_slice(&self.scratch.gpu_lights))?;
        grew |= self.directional.write(gpu, bytemuck::cast_slice(&self.scratch.gpu_directional))?;
        if !self.scratch.gpu_faces.is_empty() {
            grew |= self.faces.write(gpu, bytemuck::cast_slice(&self.scratch.gpu_faces))?;
        }
        if !all.is_empty() {
            grew |= self.draws.write(gpu, bytemuck::cast_slice(&all))?;
        }
        if grew {
            self.generation += 1;
        }
        self.active = true;
        self.faces_drawn = self.scratch.gpu_faces.len() as u32;
        self.pending_draw.store(self.faces_drawn > 0, Ordering::Relaxed);
        self.report.instance_faces = all.len() as u32;
        self.report.draw_calls = self.mesh_draws.len() as u32;
        self.report.atlas_size = atlas;
        self.report.atlas_bytes = u64::from(atlas).pow(2) * 4;
        self.report.atlas_occupancy = self.plan.occupancy(atlas);
        Ok(())
    }

    /// True once per frame whose maps need drawing: the first view's shadow pass draws them,
    /// the frame's other views read them.
    pub fn take_pending_draw(&self) -> bool {
        self.pending_draw.swap(false, Ordering::Relaxed)
    }

    /// Creates the atlas, or a larger one, when `size` does not fit the current one.
    fn ensure_atlas(&mut self, gpu: &GpuContext, size: u32) {
        if self.atlas.as_ref().is_some_and(|t| t.width() >= size) {
            return;
        }
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow_atlas"),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: SHADOW_ATLAS_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        self.atlas_view = Some(texture.create_view(&Default::default()));
        self.atlas = Some(texture);
        self.generation += 1;
        // A new texture holds no map.
        self.cache.clear();
    }
}
