//! Scene data on the GPU: view constants, lights and instances; meshes, materials and textures
//! live in [`SceneAssets`].
//!
//! `prepare` uploads what changed for a frame: meshes and textures once per distinct `Arc`
//! (and freed a few frames after the last instance using them disappears), the lights that
//! differ from what the light buffer holds, the instance buffer every frame; buffers grow when
//! the counts outgrow them.

use crate::assets::SceneAssets;
use crate::bindings::Binding;
use crate::context::{GpuContext, RenderError};
use crate::environment::EnvironmentBindings;
use crate::gpu_types::{
    GpuDirectionalLight, GpuInstance, GpuPointLight, MAX_DIRECTIONAL_LIGHTS, SHADING_GLOBAL,
    TEXTURE_SLOT_BASE_COLOR, TEXTURE_SLOT_EMISSIVE, TEXTURE_SLOT_METALLIC_ROUGHNESS, TEXTURE_SLOT_NORMAL,
    TEXTURE_SLOT_OCCLUSION, ViewUniform,
};
use crate::layouts::{GroupLayout, SCENE_GROUP};
use crate::lights::{LightReach, buffered_light, pack_directional_lights};
use crate::pool::GrowableBuffer;
use crate::shaders::ShaderDefs;
use crate::snapshot::{
    ExtractedPointLight, FrameSnapshot, LIGHT_CHUNK, LightChunk, PointLights, RenderView, aspect,
};
use glam::{Mat4, Vec4};
use manylight_core::MaterialData;
use std::sync::Arc;

/// Depth format of every pass (reverse-Z: cleared to 0, compare `Greater`).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// HDR colour format of the lighting target.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// How a draw is rasterised beyond what its pass decides: which winding faces front (the
/// instance's handedness: a mirrored transform winds its triangles the other way on screen, so
/// `front_facing` in the shaders always means the face's own front), back faces culled
/// (single-sided materials) and alpha masking. Each variant the frame draws is a pipeline of
/// every mesh pass, so opaque surfaces keep shaders without `discard` (early depth testing on
/// real GPUs) and no material branch reaches a shader (lavapipe compiles a shader again per
/// draw where it can fold a uniform branch).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SurfaceVariant {
    /// The winding that faces front.
    pub front_face: wgpu::FrontFace,
    /// Cull back faces; otherwise both sides are drawn.
    pub cull_back: bool,
    /// Discard fragments whose alpha is below the material's cutoff (`ALPHA_MASK` in
    /// `shaders/common/surface.wgsl`).
    pub alpha_mask: bool,
    /// Blended over what is behind it (glTF `BLEND`): drawn only by the transparent pass, back
    /// to front, never by the opaque passes.
    pub blend: bool,
    /// The material's texture slots, one bit per `TEXTURE_SLOT_*` (bit 0: base colour): the
    /// pipeline samples only these (`BASE_COLOR_TEXTURE` … `EMISSIVE_TEXTURE` in
    /// `shaders/common/surface.wgsl`). lavapipe runs both sides of every branch, so a slot the
    /// shader could sample costs its sample at every pixel whether the material has the
    /// texture or not.
    pub textures: u8,
    /// The material's shading model (`ShadingModel::gpu_id`), or [`SHADING_GLOBAL`] for the
    /// view's. The mesh passes make their pipelines with it [`resolved`](Self::resolved)
    /// against the view's model, so the shaders' model is the constant `SHADING_MODEL` and
    /// lavapipe does not run the other models' code for every light (it runs both sides of a
    /// branch on the material's model).
    pub shading: u32,
    /// The frame's lights cast shadows: the shaders are composed with `SHADOWS` and group 0
    /// has the shadow bindings (set per view by [`SurfaceVariant::with_view`]).
    pub shadows: bool,
    /// The view has an environment: the shaders are composed with `ENVIRONMENT` and group 0
    /// has its maps (set per view by [`SurfaceVariant::with_view`]).
    pub environment: bool,
    /// The frame traces shadow rays: the shaders are composed with `RAYS` and group 0 has the
    /// BVH (set per view by [`SurfaceVariant::with_view`]).
    pub rays: bool,
}

impl SurfaceVariant {
    /// The variant of `material` drawn with a transform whose determinant is negative when
    /// `mirrored`.
    pub fn of(material: &MaterialData, mirrored: bool) -> SurfaceVariant {
        SurfaceVariant {
            front_face: if mirrored { wgpu::FrontFace::Cw } else { wgpu::FrontFace::Ccw },
            cull_back: !material.double_sided,
            alpha_mask: material.alpha_mode.cutoff().is_some(),
            blend: material.alpha_mode == manylight_core::AlphaMode::Blend,
            textures: material
                .texture_slots()
                .iter()
                .enumerate()
                .filter(|(_, t)| t.is_some())
                .fold(0, |bits, (slot, _)| bits | 1 << slot),
            shading: material.shading.map_or(SHADING_GLOBAL, |s| s.gpu_id()),
            shadows: false,
            environment: false,
            rays: false,
        }
    }

    /// The variant for a view whose group 0 is composed with `view` (its `SHADOWS`,
    /// `ENVIRONMENT` and `RAYS`).
    pub fn with_view(self, view: ShaderDefs) -> SurfaceVariant {
        SurfaceVariant { shadows: view.shadows, environment: view.environment, rays: view.rays, ..self }
    }

    /// The shader defines of the variant.
    pub fn defs(self) -> crate::shaders::ShaderDefs {
        crate::shaders::ShaderDefs {
            shadows: self.shadows,
            environment: self.environment,
            rays: self.rays,
            ..Default::default()
        }
    }

    /// The variant with the view's model `global` (`ShadingModel::gpu_id`) where the material
    /// has none of its own.
    pub fn resolved(self, global: u32) -> SurfaceVariant {
        SurfaceVariant { shading: if self.shading == SHADING_GLOBAL { global } else { self.shading }, ..self }
    }

    /// Rasteriser state: triangle lists, winding and culling as the variant says.
    pub fn primitive(self) -> wgpu::PrimitiveState {
        wgpu::PrimitiveState {
            front_face: self.front_face,
            cull_mode: self.cull_back.then_some(wgpu::Face::Back),
            ..Default::default()
        }
    }

    /// The shader's `override` constants for the variant: `ALPHA_MASK`, one flag per texture
    /// slot in `TEXTURE_SLOT_*` order, then `SHADING_MODEL` (`SHADING_GLOBAL` when not
    /// [`resolved`](Self::resolved): each fragment reads its material's and the view's).
    pub fn constants(self) -> [(&'static str, f64); 7] {
        let flag = |on: bool| if on { 1.0 } else { 0.0 };
        let slot = |name, slot: u32| (name, flag(self.textures & 1 << slot != 0));
        [
            ("ALPHA_MASK", flag(self.alpha_mask)),
            slot("BASE_COLOR_TEXTURE", TEXTURE_SLOT_BASE_COLOR),
            slot("METALLIC_ROUGHNESS_TEXTURE", TEXTURE_SLOT_METALLIC_ROUGHNESS),
            slot("NORMAL_TEXTURE", TEXTURE_SLOT_NORMAL),
            slot("OCCLUSION_TEXTURE", TEXTURE_SLOT_OCCLUSION),
            slot("EMISSIVE_TEXTURE", TEXTURE_SLOT_EMISSIVE),
            ("SHADING_MODEL", f64::from(self.shading)),
        ]
    }
}

/// One draw: an instance of a mesh with a material.
#[derive(Clone, Copy, Debug)]
pub struct Draw {
    /// Key into [`crate::assets::SceneAssets::mesh`].
    pub mesh: usize,
    /// Key into [`crate::assets::SceneAssets::material`].
    pub material: usize,
    /// Index into the instance buffer (the draw's `first_instance`).
    pub instance: u32,
    /// Draw order: (material, mesh) upload order. Draws are batched by material and mesh in an
    /// order that does not depend on where their data lies in memory, so coplanar surfaces
    /// resolve the same way on every run.
    pub order: (u64, u64),
    /// Its pipeline variant.
    pub variant: SurfaceVariant,
    /// World-space centre of the mesh's bounds (blended draws are sorted by its distance).
    pub center: glam::Vec3,
    /// World-space box around the mesh's bounds (the shadow pass culls with it).
    pub world_bounds: manylight_core::Aabb,
    /// The instance's transform (a cached shadow map is drawn again when it changes).
    pub world_from_local: Mat4,
}

/// What group 0 binds for shadows (`crate::shadows::ShadowResources::bindings`).
pub struct ShadowBindings<'a> {
    /// The shadow atlas.
    pub atlas: &'a wgpu::TextureView,
    /// Its comparison sampler.
    pub sampler: &'a wgpu::Sampler,
    /// The lights' shadow table.
    pub lights: &'a wgpu::Buffer,
    /// The directional lights' cascades.
    pub directional: &'a wgpu::Buffer,
    /// Changes whenever one of them is re-created.
    pub generation: u64,
}

/// The shadow rays' buffers group 0 binds ([`crate::ray_geometry::ShadowRays::bindings`]).
pub struct RayBindings<'a> {
    /// The BVH's nodes (both levels).
    pub nodes: &'a wgpu::Buffer,
    /// The triangles, the instances and the casting lights' bits.
    pub prims: &'a wgpu::Buffer,
    /// The instance level's root and the offsets in `prims` (the view uniform's `rays`).
    pub view: [u32; 4],
    /// Changes whenever one of the buffers is re-created.
    pub generation: u64,
}

/// What a frame needs to know of a chunk of lights without visiting them again: how many are
/// invalid, and the box of what the valid ones reach.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct ChunkSummary {
    invalid: u32,
    reach: LightReach,
}

impl ChunkSummary {
    fn of(lights: &[ExtractedPointLight]) -> ChunkSummary {
        let mut summary = ChunkSummary::default();
        for light in lights {
            if light.is_valid() {
                summary.reach.add(light);
            } else {
                summary.invalid += 1;
            }
        }
        summary
    }
}

/// A group 0 and the generations of the buffers (lights, instances, shadows, environment, rays)
/// it was made from.
type BoundView = ((u64, u64, u64, u64, u64), wgpu::BindGroup);

/// Scene data on the GPU for the current frame: group 0 and the view constants
/// ([`ViewBindings`]), the lights ([`SceneLights`]), the instances and their draws
/// ([`SceneInstances`]), the meshes and materials ([`SceneAssets`]) and the tone map's
/// non-finite counter.
pub struct SceneResources {
    /// Group 0 of the scene passes and the view uniform.
    pub view: ViewBindings,
    /// The point, spot and directional lights as the shaders read them.
    pub lights: SceneLights,
    /// The instances and the frame's draws.
    pub instances: SceneInstances,
    /// The tone map's count of non-finite HDR pixels.
    pub nonfinite: NonFiniteCounter,
    /// Meshes, materials, textures and samplers on the GPU, and the material layout.
    pub assets: SceneAssets,
}

/// Group 0 of every scene pass ([`SCENE_GROUP`]) and the view constants it holds.
pub struct ViewBindings {
    /// Layout of group 0 for this view: view uniform, lights, instances, the shadow bindings
    /// when [`ViewBindings::shadows_active`] and the environment's when
    /// [`ViewBindings::environment_active`].
    pub layout: GroupLayout,
    /// Group 0's layouts, by [`flavor`]: without and with shadow maps, without and with an
    /// environment, without and with shadow rays.
    layouts: [GroupLayout; FLAVORS],
    /// This frame's lights cast shadows: group 0 holds the shadow bindings and every shading
    /// pipeline is composed with `SHADOWS`.
    pub shadows_active: bool,
    /// The view has an environment: group 0 holds its maps and the surface pipelines are
    /// composed with `ENVIRONMENT`.
    pub environment_active: bool,
    /// This frame traces shadow rays: group 0 holds the BVH and the casting lights' bits and
    /// every shading pipeline is composed with `RAYS`.
    pub rays_active: bool,
    /// The shadow rays' root and offsets the view uniform carries (`ViewUniform::rays`).
    pub rays: [u32; 4],
    /// Group 0 for this frame.
    pub bind_group: wgpu::BindGroup,
    /// The view uniform buffer.
    pub buffer: wgpu::Buffer,
    /// The frame's view constants as uploaded.
    pub uniform: ViewUniform,
    /// Group 0 of each [`flavor`], as last made.
    bound: [Option<BoundView>; FLAVORS],
}

/// Group 0's layouts: each combination of shadow maps, an environment and shadow rays.
const FLAVORS: usize = 8;

/// The index of a group 0 layout: shadow maps in bit 0, an environment in bit 1, shadow rays in
/// bit 2.
fn flavor(shadows: bool, environment: bool, rays: bool) -> usize {
    usize::from(shadows) | usize::from(environment) << 1 | usize::from(rays) << 2
}

impl ViewBindings {
    /// The defines group 0's bindings this view are composed with (`SHADOWS`, `ENVIRONMENT`).
    pub fn defs(&self) -> ShaderDefs {
        ShaderDefs {
            shadows: self.shadows_active,
            environment: self.environment_active,
            rays: self.rays_active,
            ..Default::default()
        }
    }
}

/// The frame's lights on the GPU: the point and spot lights' buffer (written only where lights
/// changed), the directional lights the view uniform carries, and what the frame counted.
pub struct SceneLights {
    /// Point lights (storage; at least one element).
    pub buffer: GrowableBuffer,
    /// Point and spot lights in the light buffer this frame (invalid ones included: they keep
    /// their index and light nothing).
    pub count: u32,
    /// The invalid ones among them.
    pub invalid_point_lights: u32,
    /// This frame's directional lights as every view's uniform carries them.
    pub directional: [GpuDirectionalLight; MAX_DIRECTIONAL_LIGHTS as usize],
    /// Directional lights in `directional`.
    pub directional_count: u32,
    /// Valid directional lights past [`MAX_DIRECTIONAL_LIGHTS`], not drawn.
    pub dropped_directional_lights: u32,
    /// Bytes written to the light buffer this frame (once per frame, whatever the views; only
    /// the lights that changed).
    pub upload_bytes: u64,
    /// Lights dropped for invalid parameters this frame.
    pub invalid_lights: u32,
    /// The box around what the uploaded lights can reach (the cluster grids slice a projection
    /// without a far plane to it).
    pub reach: LightReach,
    /// The chunks of lights the light buffer holds: a frame packs and writes only the lights
    /// of chunks that are not these, and of those only the lights that differ.
    uploaded_chunks: Vec<Arc<LightChunk>>,
    /// Per chunk of the light list: its invalid lights and the box of what its valid ones reach,
    /// made when the chunk changed (a frame merges them, one per chunk, not one per light).
    chunk_summaries: Vec<ChunkSummary>,
    /// One run of changed lights, packed (kept between frames so that it is not allocated
    /// again).
    packed: Vec<GpuPointLight>,
    /// The motions of the lights that animate on the GPU, and the pass that applies them.
    pub motions: crate::animation::LightMotions,
}

/// The frame's instances on the GPU and the draws made of them.
pub struct SceneInstances {
    /// Instance transforms (storage).
    pub buffer: GrowableBuffer,
    /// Draws sorted by material then mesh.
    pub draws: Vec<Draw>,
    /// The distinct variants of this frame's draws, in first-drawn order: the pipelines each
    /// mesh pass needs.
    pub variants: Vec<SurfaceVariant>,
    /// The blended draws (indices into `draws`) of the current view, farthest first.
    pub blended: Vec<usize>,
    /// This frame's instances as packed, and the ones the instance buffer held before (what a
    /// frame compares with to write only the instances that changed).
    packed: Vec<GpuInstance>,
    uploaded: Vec<GpuInstance>,
    /// Instances not drawn this frame because their transform is not finite.
    pub invalid_instances: u32,
    /// Instances not drawn this frame because their transform collapses the mesh to a line or
    /// a point (a zero scale on two or three axes, on the mesh or a parent): they cover no pixel.
    pub collapsed_instances: u32,
}

/// A GPU counter of pixels whose HDR colour is NaN or infinite, written by the tone map and
/// read back into [`FrameReport::nonfinite_pixels`](crate::stats::FrameReport).
pub struct NonFiniteCounter {
    /// The `atomic<u32>` the tone map increments (cleared by the pass before it draws; the
    /// renderer copies it into the frame's read-back slot after the view).
    pub counter: wgpu::Buffer,
}

impl NonFiniteCounter {
    fn new(gpu: &GpuContext) -> NonFiniteCounter {
        use wgpu::BufferUsages as U;
        NonFiniteCounter {
            counter: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("nonfinite_pixels"),
                size: 4,
                usage: U::STORAGE | U::COPY_SRC | U::COPY_DST,
                mapped_at_creation: false,
            }),
        }
    }
}

impl SceneResources {
    /// Creates the layouts and empty buffers.
    pub fn new(gpu: &GpuContext) -> SceneResources {
        let device = &gpu.device;
        let layouts: [GroupLayout; FLAVORS] = std::array::from_fn(|i| {
            let (shadows, environment, rays) = (i & 1 != 0, i & 2 != 0, i & 4 != 0);
            SCENE_GROUP.create_layout(device, ShaderDefs { shadows, environment, rays, ..Default::default() })
        });
        let view_layout = layouts[flavor(false, false, false)].clone();
        let view_buffer = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("view_uniform"),
            size: std::mem::size_of::<ViewUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let storage_usage = wgpu::BufferUsages::STORAGE;
        // One placeholder light (every pipeline binds the buffer); it grows when lights appear.
        let light_bytes = std::mem::size_of::<GpuPointLight>() as u64;
        let lights = GrowableBuffer::new(gpu, "point_lights", storage_usage, light_bytes);
        let instances = GrowableBuffer::new(gpu, "instances", storage_usage, 64 * 128);
        let view_bind_group = Self::make_view_bind_group(
            gpu,
            &view_layout,
            [&view_buffer, lights.buffer(), instances.buffer()],
            None,
            None,
            None,
        );
        SceneResources {
            view: ViewBindings {
                layout: view_layout,
                layouts,
                shadows_active: false,
                environment_active: false,
                rays_active: false,
                rays: [manylight_core::ray_bvh::RAY_NO_NODE, 0, 0, 0],
                bind_group: view_bind_group,
                buffer: view_buffer,
                uniform: ViewUniform::zeroed_default(),
                bound: Default::default(),
            },
            lights: SceneLights {
                buffer: lights,
                count: 0,
                invalid_point_lights: 0,
                directional: [GpuDirectionalLight::default(); MAX_DIRECTIONAL_LIGHTS as usize],
                directional_count: 0,
                dropped_directional_lights: 0,
                upload_bytes: 0,
                invalid_lights: 0,
                reach: LightReach::default(),
                uploaded_chunks: Vec::new(),
                chunk_summaries: Vec::new(),
                packed: Vec::new(),
                motions: Default::default(),
            },
            instances: SceneInstances {
                buffer: instances,
                draws: Vec::new(),
                variants: Vec::new(),
                blended: Vec::new(),
                packed: Vec::new(),
                uploaded: Vec::new(),
                invalid_instances: 0,
                collapsed_instances: 0,
            },
            nonfinite: NonFiniteCounter::new(gpu),
            assets: SceneAssets::new(gpu),
        }
    }

    /// Group 0 of `layout`: `base` (the view uniform, the lights and the instances), then the
    /// shadow maps', the environment's and the shadow rays' bindings that are given.
    fn make_view_bind_group(
        gpu: &GpuContext,
        layout: &GroupLayout,
        base: [&wgpu::Buffer; 3],
        shadows: Option<&ShadowBindings<'_>>,
        environment: Option<&EnvironmentBindings<'_>>,
        rays: Option<&RayBindings<'_>>,
    ) -> wgpu::BindGroup {
        let mut resources = base.map(Binding::Buffer).to_vec();
        if let Some(shadows) = shadows {
            resources.extend([
                Binding::Texture(shadows.atlas),
                Binding::Sampler(shadows.sampler),
                Binding::Buffer(shadows.lights),
                Binding::Buffer(shadows.directional),
            ]);
        }
        if let Some(environment) = environment {
            resources.extend([
                Binding::Texture(environment.specular),
                Binding::Texture(environment.irradiance),
                Binding::Texture(environment.lut),
                Binding::Sampler(environment.sampler),
            ]);
        }
        if let Some(rays) = rays {
            resources.extend([Binding::Buffer(rays.nodes), Binding::Buffer(rays.prims)]);
        }
        layout.create_bind_group(gpu, &resources)
    }

    /// Binds group 0 for a view (after [`SceneResources::prepare`], the shadows' and the
    /// environments' `prepare`): with the shadow atlas, its sampler and light table when
    /// `shadows` is given, with the environment's maps when `environment` is, else without
    /// them, and with the shadow rays' buffers when `rays` is. One group of each combination
    /// is kept, so views that differ only in their shadows checkbox or environment switch
    /// between them; each is re-created only when a buffer, the atlas or the environment
    /// changed.
    pub fn bind_view(
        &mut self,
        gpu: &GpuContext,
        shadows: Option<ShadowBindings<'_>>,
        environment: Option<EnvironmentBindings<'_>>,
        rays: Option<RayBindings<'_>>,
    ) {
        let index = flavor(shadows.is_some(), environment.is_some(), rays.is_some());
        let generations = (
            self.lights.buffer.generation(),
            self.instances.buffer.generation(),
            shadows.as_ref().map_or(0, |s| s.generation + 1),
            environment.as_ref().map_or(0, |e| e.generation + 1),
            rays.as_ref().map_or(0, |r| r.generation + 1),
        );
        let layout = &self.view.layouts[index];
        let slot = &mut self.view.bound[index];
        if slot.as_ref().is_none_or(|(g, _)| *g != generations) {
            let group = Self::make_view_bind_group(
                gpu,
                layout,
                [&self.view.buffer, self.lights.buffer.buffer(), self.instances.buffer.buffer()],
                shadows.as_ref(),
                environment.as_ref(),
                rays.as_ref(),
            );
            *slot = Some((generations, group));
        }
        if let Some((_, group)) = slot {
            self.view.bind_group = group.clone();
        }
        self.view.shadows_active = shadows.is_some();
        self.view.environment_active = environment.is_some();
        self.view.rays_active = rays.is_some();
        self.view.rays = rays.map_or([manylight_core::ray_bvh::RAY_NO_NODE, 0, 0, 0], |r| r.view);
        self.view.layout = layout.clone();
    }

    /// Writes the view constants of `view` (before each view's submission: the views of a
    /// frame share the lights and instances that [`SceneResources::prepare`] uploaded once).
    pub fn prepare_view(&mut self, gpu: &GpuContext, view: &RenderView) {
        let lights = &self.lights;
        self.view.uniform = view_uniform(view, lights.count, lights.directional_count, lights.directional);
        self.view.uniform.rays = self.view.rays;
        gpu.write_buffer(&self.view.buffer, 0, bytemuck::bytes_of(&self.view.uniform));
        // Blended draws, farthest first along the view direction (view-space z ascending).
        let view_from_world = self.view.uniform.view_from_world;
        let draws = &self.instances.draws;
        self.instances.blended.clear();
        self.instances.blended.extend((0..draws.len()).filter(|&i| draws[i].variant.blend));
        self.instances.blended.sort_by(|&a, &b| {
            let z = |i: usize| view_from_world.transform_point3(draws[i].center).z;
            z(a).total_cmp(&z(b)).then(a.cmp(&b))
        });
    }

    /// Writes the lights of `lights` that differ from what the light buffer holds: a chunk the
    /// buffer holds already (the same `Arc`) is skipped without looking at its lights, and of
    /// a changed chunk only the runs of lights that differ are packed and written (a still
    /// scene uploads nothing after its first frame; moving lights, their own bytes). Updates
    /// the chunks' summaries. Returns the bytes written.
    fn upload_lights(&mut self, gpu: &GpuContext, lights: &PointLights, t: f32) -> Result<u64, RenderError> {
        let element = std::mem::size_of::<GpuPointLight>();
        // At least one light: every pipeline binds the buffer (a new buffer is zeroed). A new
        // light or motion buffer is written whole.
        let new_lights = self.lights.buffer.reserve(gpu, (lights.len().max(1) * element) as u64)?;
        if self.lights.motions.reserve(gpu, lights)? | new_lights {
            self.lights.uploaded_chunks.clear();
        }
        let mut written = 0;
        self.lights.chunk_summaries.resize(lights.chunks().len(), ChunkSummary::default());
        for (k, chunk) in lights.chunks().iter().enumerate() {
            let old = self.lights.uploaded_chunks.get(k);
            if old.is_some_and(|o| Arc::ptr_eq(o, chunk)) {
                continue;
            }
            self.lights.chunk_summaries[k] = ChunkSummary::of(chunk.lights());
            let (old, new) = (old.map_or(&[][..], |o| o.lights()), chunk.lights());
            let mut i = 0;
            while i < new.len() {
                if old.get(i) == Some(&new[i]) {
                    i += 1;
                    continue;
                }
                let start = i;
                while i < new.len() && old.get(i) != Some(&new[i]) {
                    i += 1;
                }
                self.lights.packed.clear();
                self.lights.packed.extend(new[start..i].iter().map(buffered_light));
                let offset = ((k * LIGHT_CHUNK + start) * element) as u64;
                gpu.write_buffer(
                    self.lights.buffer.buffer(),
                    offset,
                    bytemuck::cast_slice(&self.lights.packed),
                );
                written += (self.lights.packed.len() * element) as u64;
                written += self.lights.motions.write(gpu, k * LIGHT_CHUNK + start, &new[start..i], t);
            }
        }
        written += self.lights.motions.refresh_epochs(gpu, lights, t);
        // The chunks as the buffer now holds them (the Vec keeps its allocation).
        self.lights.uploaded_chunks.clear();
        self.lights.uploaded_chunks.extend(lights.chunks().iter().cloned());
        Ok(written)
    }

    /// Uploads the frame's lights, instances and any new meshes/materials/textures, once per
    /// frame whatever the number of views.
    pub fn prepare(&mut self, gpu: &GpuContext, snapshot: &FrameSnapshot) -> Result<(), RenderError> {
        self.assets.begin_frame();

        // Lights: invalid ones (NaN, inf, negative) keep their place as zeroed lights that
        // reach nothing, and are counted.
        self.lights.upload_bytes = self.upload_lights(gpu, &snapshot.lights, snapshot.elapsed_secs)?;
        self.lights.count = snapshot.lights.len() as u32;
        // Animated lights take their place for the frame's time before any view reads them.
        self.lights.upload_bytes += self.lights.motions.prepare(
            gpu,
            &self.lights.buffer,
            self.lights.count,
            snapshot.elapsed_secs,
        )?;
        self.lights.reach = LightReach::default();
        self.lights.invalid_point_lights = 0;
        for summary in &self.lights.chunk_summaries {
            self.lights.reach.merge(&summary.reach);
            self.lights.invalid_point_lights += summary.invalid;
        }
        self.lights.invalid_lights = self.lights.invalid_point_lights;
        // Directional lights: the first MAX_DIRECTIONAL_LIGHTS valid ones, in the view uniform.
        let directional = pack_directional_lights(&snapshot.directional_lights);
        self.lights.invalid_lights += directional.invalid;
        self.lights.directional = directional.packed;
        self.lights.directional_count = directional.count;
        self.lights.dropped_directional_lights = directional.dropped;
        if self.lights.dropped_directional_lights > 0 {
            tracing::warn!(
                "{} directional lights past the first {MAX_DIRECTIONAL_LIGHTS} are not drawn",
                self.lights.dropped_directional_lights
            );
        }

        // Meshes, materials, instances.
        // Last frame's instances become the comparison; this frame's are packed into the other
        // Vec (both keep their allocations).
        std::mem::swap(&mut self.instances.packed, &mut self.instances.uploaded);
        let mut instance_data = std::mem::take(&mut self.instances.packed);
        instance_data.clear();
        self.instances.draws.clear();
        (self.instances.invalid_instances, self.instances.collapsed_instances) = (0, 0);
        for inst in &snapshot.instances {
            if !inst.world_from_local.is_finite() {
                tracing::debug!("skipping instance of `{}`: non-finite transform", inst.mesh.label);
                self.instances.invalid_instances += 1;
                continue;
            }
            let Some(gpu_instance) = GpuInstance::drawable(inst.world_from_local) else {
                self.instances.collapsed_instances += 1;
                continue;
            };
            if inst.mesh.indices.is_empty() {
                continue;
            }
            let (mesh, mesh_order, local_center, local_bounds) = self.assets.mesh_entry(gpu, &inst.mesh)?;
            let (material, material_order) = self.assets.material_entry(gpu, &inst.material)?;
            let order = (material_order, mesh_order);
            let mirrored = glam::Mat3::from_mat4(inst.world_from_local).determinant() < 0.0;
            let variant = SurfaceVariant::of(&inst.material, mirrored);
            let center = inst.world_from_local.transform_point3(local_center);
            let instance = instance_data.len() as u32;
            let world_bounds = local_bounds.transformed(&inst.world_from_local);
            self.instances.draws.push(Draw {
                mesh,
                material,
                instance,
                order,
                variant,
                center,
                world_bounds,
                world_from_local: inst.world_from_local,
            });
            instance_data.push(gpu_instance);
        }
        self.instances.draws.sort_by_key(|d| d.order);
        self.instances.variants.clear();
        for d in &self.instances.draws {
            if !self.instances.variants.contains(&d.variant) {
                self.instances.variants.push(d.variant);
            }
        }
        if instance_data.is_empty() {
            instance_data.push(GpuInstance::new(Mat4::IDENTITY));
        }
        // Only the instances that differ from the buffer's: still objects upload nothing.
        let element = std::mem::size_of::<GpuInstance>();
        let previous = bytemuck::cast_slice(&self.instances.uploaded);
        self.instances.buffer.write_changed(
            gpu,
            bytemuck::cast_slice(&instance_data),
            Some(previous),
            element,
        )?;
        self.instances.packed = instance_data;

        self.assets.evict_unused();
        Ok(())
    }
}

fn viewport_vec(size: glam::UVec2) -> Vec4 {
    let (w, h) = (size.x.max(1) as f32, size.y.max(1) as f32);
    Vec4::new(w, h, 1.0 / w, 1.0 / h)
}

impl ViewUniform {
    /// Identity matrices, zero lights.
    pub fn zeroed_default() -> ViewUniform {
        ViewUniform {
            clip_from_world: Mat4::IDENTITY,
            view_from_world: Mat4::IDENTITY,
            clip_from_view: Mat4::IDENTITY,
            world_from_clip: Mat4::IDENTITY,
            prev_clip_from_world: Mat4::IDENTITY,
            camera_position: Vec4::W,
            viewport: Vec4::ONE,
            params: Vec4::new(0.1, 1000.0, 1.0, 0.0),
            env_from_world: Mat4::IDENTITY,
            sky_from_world: Mat4::IDENTITY,
            environment: Vec4::ZERO,
            rays: [manylight_core::ray_bvh::RAY_NO_NODE, 0, 0, 0],
            light_count: 0,
            shading_model: 0,
            directional_count: 0,
            _pad: 0,
            directional: [GpuDirectionalLight::default(); MAX_DIRECTIONAL_LIGHTS as usize],
        }
    }
}

/// The view constants of `view` (group 0's `view`, `ViewUniform` in `common/view.wgsl`), with
/// the frame's point-light count and directional lights.
pub(crate) fn view_uniform(
    view: &RenderView,
    light_count: u32,
    directional_count: u32,
    directional: [GpuDirectionalLight; MAX_DIRECTIONAL_LIGHTS as usize],
) -> ViewUniform {
    let size = view.size;
    let settings = &view.settings;
    match &view.camera {
        Some(cam) => {
            let clip_from_view = cam.projection.matrix(aspect(size));
            let view_from_world = cam.view_from_world();
            let clip_from_world = clip_from_view * view_from_world;
            let p = cam.projection.sanitized();
            // near / far rather than far: 0 for an infinite projection, never infinite.
            ViewUniform {
                clip_from_world,
                view_from_world,
                clip_from_view,
                world_from_clip: clip_from_world.inverse(),
                prev_clip_from_world: cam.prev_clip_from_world.unwrap_or(clip_from_world),
                camera_position: cam.position().extend(1.0),
                viewport: viewport_vec(size),
                params: Vec4::new(p.near, p.near_over_far(), view.exposure(), settings.ambient),
                env_from_world: Mat4::from_quat(
                    cam.environment.map_or(glam::Quat::IDENTITY, |e| e.rotation).inverse(),
                ),
                sky_from_world: Mat4::from_quat(
                    cam.skybox.map_or(glam::Quat::IDENTITY, |s| s.rotation).inverse(),
                ),
                environment: Vec4::new(
                    cam.environment.map_or(0.0, |e| e.intensity),
                    (settings.environment_filter.specular_mips() - 1) as f32,
                    cam.skybox.map_or(0.0, |s| s.brightness),
                    0.0,
                ),
                rays: [manylight_core::ray_bvh::RAY_NO_NODE, 0, 0, 0],
                light_count,
                shading_model: settings.shading.gpu_id(),
                directional_count,
                _pad: 0,
                directional,
            }
        }
        None => ViewUniform { viewport: viewport_vec(size), light_count, ..ViewUniform::zeroed_default() },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use manylight_core::material::{MaterialTexture, ShadingModel, TextureData};
    use std::sync::Arc;

    #[test]
    fn a_surface_variant_samples_exactly_its_materials_texture_slots() {
        let image = Arc::new(TextureData {
            label: "t".into(),
            width: 1,
            height: 1,
            rgba8: vec![255; 4],
            srgb: false,
        });
        let plain = MaterialData::default();
        let v = SurfaceVariant::of(&plain, false);
        assert_eq!(v.textures, 0);
        assert!(v.constants()[1..6].iter().all(|&(_, value)| value == 0.0), "{:?}", v.constants());

        let mapped = MaterialData {
            normal_texture: Some(MaterialTexture::new(image.clone())),
            emissive_texture: Some(MaterialTexture::new(image)),
            ..MaterialData::default()
        };
        let v = SurfaceVariant::of(&mapped, false);
        assert_eq!(v.textures, 1 << TEXTURE_SLOT_NORMAL | 1 << TEXTURE_SLOT_EMISSIVE);
        let on: Vec<&str> =
            v.constants()[1..6].iter().filter(|&&(_, value)| value == 1.0).map(|&(n, _)| n).collect();
        assert_eq!(on, ["NORMAL_TEXTURE", "EMISSIVE_TEXTURE"]);
        // Materials with other slots draw with other pipelines.
        assert_ne!(v, SurfaceVariant::of(&plain, false));
    }

    #[test]
    fn a_surface_variant_fixes_its_materials_shading_model_or_the_views() {
        let model =
            |v: SurfaceVariant| v.constants().into_iter().find(|&(n, _)| n == "SHADING_MODEL").map(|c| c.1);
        let own = MaterialData { shading: Some(ShadingModel::Toon), ..MaterialData::default() };
        let v = SurfaceVariant::of(&own, false);
        let toon = f64::from(ShadingModel::Toon.gpu_id());
        assert_eq!(model(v), Some(toon));
        // The material's own model wins over the view's.
        assert_eq!(model(v.resolved(ShadingModel::Pbr.gpu_id())), Some(toon));
        // Without one, each fragment reads the view's, until resolved against it.
        let plain = SurfaceVariant::of(&MaterialData::default(), false);
        assert_eq!(model(plain), Some(f64::from(SHADING_GLOBAL)));
        let lambert = plain.resolved(ShadingModel::Lambert.gpu_id());
        assert_eq!(model(lambert), Some(f64::from(ShadingModel::Lambert.gpu_id())));
        assert_ne!(plain, v);
    }
}
