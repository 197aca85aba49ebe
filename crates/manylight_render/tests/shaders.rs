//! Every WGSL file parses and validates with naga, and the structs shared with Rust have the
//! same size and field offsets on both sides. No GPU needed.

use manylight_core::ray_bvh::{BvhNode, RayInstance, RayTriangle};
use manylight_render::GBufferLayout;
use manylight_render::gpu_types::{
    GpuCascade, GpuDirectionalShadow, GpuShadowDraw, GpuShadowFace, GpuShadowLight, GpuShadowProbe,
};
use manylight_render::gpu_types::{
    GpuClusterBounds, GpuClusterCounters, GpuClusterParams, GpuDirectionalLight, GpuInstance,
    GpuLightAnimationParams, GpuLightMotion, GpuMaterial, GpuPointLight, GpuTextureUv, ViewUniform,
};
use manylight_render::layouts::{BindingKind, Presence, SHADER_BIND_GROUPS, shader_bind_groups};
use manylight_render::ray_geometry::{GpuRayProbeParams, GpuRaySegment};
use manylight_render::resources::SurfaceVariant;
use manylight_render::shaders::{SOURCES, ShaderDefs, compose, compose_with};
use std::mem::{offset_of, size_of};

fn validate(path: &str) -> naga::Module {
    validate_with(path, ShaderDefs::default())
}

fn validate_with(path: &str, defs: ShaderDefs) -> naga::Module {
    let code = compose_with(path, defs).unwrap_or_else(|e| panic!("{path}: {e}"));
    let module = naga::front::wgsl::parse_str(&code)
        .unwrap_or_else(|e| panic!("{path} ({defs:?}): {}", e.emit_to_string(&code)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{path} ({defs:?}): {}", e.emit_to_string(&code)));
    module
}

/// No G-buffer layout, then each.
const GBUFFER_CHOICES: [Option<GBufferLayout>; 4] =
    [None, Some(GBufferLayout::Full), Some(GBufferLayout::Packed), Some(GBufferLayout::Compact)];

/// Every combination of the defines a shader can be composed with.
fn all_defs() -> Vec<ShaderDefs> {
    let mut out = Vec::new();
    for shadows in [false, true] {
        for clip_distances in [false, true] {
            for gbuffer in GBUFFER_CHOICES {
                for environment in [false, true] {
                    for rays in [false, true] {
                        out.push(ShaderDefs { shadows, clip_distances, gbuffer, environment, rays });
                    }
                }
            }
        }
    }
    out
}

/// The G-buffer layout is chosen when a shader is composed, so no entry point is copied per
/// layout: none is named after one, and the shaders that read or write the G-buffer have their
/// G-buffer entry points (`fs_main`, `cs_main`, `cs_gbuffer`, `fs_ambient`, `fs_volume`) only
/// when composed for a layout.
#[test]
fn no_entry_point_is_copied_per_gbuffer_layout() {
    let mut with_layout = Vec::new();
    for (path, _) in SOURCES {
        let plain = validate(path).entry_points.len();
        for defs in all_defs() {
            let module = validate_with(path, defs);
            for ep in &module.entry_points {
                let lower = ep.name.to_lowercase();
                assert!(
                    !lower.split('_').any(|word| ["full", "packed", "compact"].contains(&word)),
                    "{path}: entry point `{}` is named after a G-buffer layout",
                    ep.name
                );
            }
            if defs == (ShaderDefs { gbuffer: defs.gbuffer, ..Default::default() })
                && module.entry_points.len() > plain
            {
                with_layout.push(*path);
            }
        }
    }
    with_layout.dedup();
    with_layout.sort();
    with_layout.dedup();
    let expected = [
        "cluster_depth.wgsl",
        "deferred_lighting.wgsl",
        "gbuffer.wgsl",
        "light_refine.wgsl",
        "light_volumes.wgsl",
        "tiled_deferred.wgsl",
    ];
    assert_eq!(with_layout, expected);
}

#[test]
fn every_embedded_shader_validates() {
    for (path, _) in SOURCES {
        for defs in all_defs() {
            validate_with(path, defs);
        }
    }
}

#[test]
fn shadow_code_and_bindings_appear_only_with_shadows() {
    for path in [
        "forward.wgsl",
        "clustered_forward.wgsl",
        "deferred_lighting.wgsl",
        "tiled_deferred.wgsl",
        "light_volumes.wgsl",
    ] {
        let plain = compose(path).unwrap();
        let shadowed = compose_with(path, ShaderDefs { shadows: true, ..Default::default() }).unwrap();
        assert!(!plain.contains("shadow_atlas") && !plain.contains("shadow_visibility"), "{path}");
        assert!(shadowed.contains("var shadow_atlas") && shadowed.contains("shadow_visibility(k"), "{path}");
    }
    let clipped =
        compose_with("shadow_maps.wgsl", ShaderDefs { clip_distances: true, ..Default::default() }).unwrap();
    assert!(clipped.starts_with("enable clip_distances;"), "the directive leads the module");
    assert!(!compose("shadow_maps.wgsl").unwrap().contains("enable clip_distances"));
}

#[test]
fn every_wgsl_file_on_disk_is_embedded() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/shaders");
    let mut stack = vec![std::path::PathBuf::from(root)];
    let mut found = Vec::new();
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "wgsl") {
                let rel = path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
                found.push(rel);
            }
        }
    }
    assert!(!found.is_empty());
    for rel in found {
        let embedded = SOURCES.iter().find(|(p, _)| *p == rel);
        let on_disk = std::fs::read_to_string(format!("{root}/{rel}")).unwrap();
        assert_eq!(embedded.map(|(_, s)| *s), Some(on_disk.as_str()), "{rel} is not embedded or differs");
    }
}

/// Size and member offsets of a WGSL struct.
fn wgsl_layout(module: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
    for (_, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(name)
            && let naga::TypeInner::Struct { members, span } = &ty.inner
        {
            return (*span, members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect());
        }
    }
    panic!("struct {name} not found");
}

fn offsets(module: &naga::Module, name: &str, size: usize, rust: &[(&str, usize)]) {
    let (span, members) = wgsl_layout(module, name);
    assert_eq!(span as usize, size, "size of {name}");
    for (field, offset) in rust {
        let wgsl = members
            .iter()
            .find(|(n, _)| n == field)
            .unwrap_or_else(|| panic!("{name}.{field} missing in WGSL"));
        assert_eq!(wgsl.1 as usize, *offset, "offset of {name}.{field}");
    }
}

/// Every `f32` constant of the preamble, as written (`{:?}`), is a finite `f32` when read back
/// exactly: Tint (Chromium's WGSL compiler) refuses a literal past `f32::MAX` where naga rounds
/// it, so `f32::MAX` written as 3.4028235e38 fails in a browser only.
#[test]
fn every_shared_float_constant_is_written_within_f32_range() {
    for (name, value) in manylight_render::gpu_types::shared_f32_constants() {
        let written = format!("{value:?}");
        let exact: f64 = written.parse().expect("a decimal");
        assert!(exact.abs() <= f64::from(f32::MAX), "{name} is written {written}, past f32::MAX");
    }
}

#[test]
fn shared_structs_match_rust() {
    let shadowed = validate_with("forward.wgsl", ShaderDefs { shadows: true, ..Default::default() });
    offsets(
        &shadowed,
        "GpuShadowLight",
        size_of::<GpuShadowLight>(),
        &[
            ("tile", offset_of!(GpuShadowLight, tile)),
            ("params", offset_of!(GpuShadowLight, params)),
            ("origin", offset_of!(GpuShadowLight, origin)),
        ],
    );
    offsets(
        &shadowed,
        "GpuCascade",
        size_of::<GpuCascade>(),
        &[
            ("clip_from_world", offset_of!(GpuCascade, clip_from_world)),
            ("tile", offset_of!(GpuCascade, tile)),
            ("params", offset_of!(GpuCascade, params)),
        ],
    );
    offsets(
        &shadowed,
        "GpuDirectionalShadow",
        size_of::<GpuDirectionalShadow>(),
        &[
            ("cascades", offset_of!(GpuDirectionalShadow, cascades)),
            ("count", offset_of!(GpuDirectionalShadow, count)),
            ("bias", offset_of!(GpuDirectionalShadow, bias)),
        ],
    );
    let shadow_maps = validate("shadow_maps.wgsl");
    offsets(
        &shadow_maps,
        "GpuShadowFace",
        size_of::<GpuShadowFace>(),
        &[
            ("clip_from_world", offset_of!(GpuShadowFace, clip_from_world)),
            ("atlas", offset_of!(GpuShadowFace, atlas)),
        ],
    );
    offsets(
        &shadow_maps,
        "GpuShadowDraw",
        size_of::<GpuShadowDraw>(),
        &[("instance", offset_of!(GpuShadowDraw, instance)), ("face", offset_of!(GpuShadowDraw, face))],
    );
    let animation = validate("light_animation.wgsl");
    offsets(
        &animation,
        "GpuLightMotion",
        size_of::<GpuLightMotion>(),
        &[
            ("center", offset_of!(GpuLightMotion, center)),
            ("orbit_radius", offset_of!(GpuLightMotion, orbit_radius)),
            ("color", offset_of!(GpuLightMotion, color)),
            ("bob_amplitude", offset_of!(GpuLightMotion, bob_amplitude)),
            ("speeds", offset_of!(GpuLightMotion, speeds)),
            ("angles", offset_of!(GpuLightMotion, angles)),
            ("flicker2_speed", offset_of!(GpuLightMotion, flicker2_speed)),
            ("flicker2_angle", offset_of!(GpuLightMotion, flicker2_angle)),
            ("epoch", offset_of!(GpuLightMotion, epoch)),
            ("intensity", offset_of!(GpuLightMotion, intensity)),
            ("animated", offset_of!(GpuLightMotion, animated)),
        ],
    );
    offsets(
        &animation,
        "LightAnimationParams",
        size_of::<GpuLightAnimationParams>(),
        &[
            ("elapsed_secs", offset_of!(GpuLightAnimationParams, elapsed_secs)),
            ("light_count", offset_of!(GpuLightAnimationParams, light_count)),
        ],
    );
    offsets(
        &validate("shadow_probe.wgsl"),
        "GpuShadowProbe",
        size_of::<GpuShadowProbe>(),
        &[
            ("position", offset_of!(GpuShadowProbe, position)),
            ("light", offset_of!(GpuShadowProbe, light)),
            ("normal", offset_of!(GpuShadowProbe, normal)),
        ],
    );
    let rays = validate("ray_probe.wgsl");
    offsets(
        &rays,
        "RayNode",
        size_of::<BvhNode>(),
        &[
            ("min", offset_of!(BvhNode, min)),
            ("count", offset_of!(BvhNode, count)),
            ("max", offset_of!(BvhNode, max)),
            ("first", offset_of!(BvhNode, first)),
        ],
    );
    offsets(
        &rays,
        "RayTriangle",
        size_of::<RayTriangle>(),
        &[
            ("v0", offset_of!(RayTriangle, v0)),
            ("e1", offset_of!(RayTriangle, e1)),
            ("e2", offset_of!(RayTriangle, e2)),
        ],
    );
    offsets(
        &rays,
        "RayInstance",
        size_of::<RayInstance>(),
        &[
            ("local_from_world", offset_of!(RayInstance, local_from_world)),
            ("root", offset_of!(RayInstance, root)),
        ],
    );
    offsets(
        &rays,
        "GpuRaySegment",
        size_of::<GpuRaySegment>(),
        &[
            ("origin", offset_of!(GpuRaySegment, origin)),
            ("t_max", offset_of!(GpuRaySegment, t_max)),
            ("direction", offset_of!(GpuRaySegment, direction)),
        ],
    );
    offsets(
        &rays,
        "GpuRayProbeParams",
        size_of::<GpuRayProbeParams>(),
        &[
            ("geometry", offset_of!(GpuRayProbeParams, geometry)),
            ("count", offset_of!(GpuRayProbeParams, count)),
        ],
    );
    let forward = validate("forward.wgsl");
    offsets(
        &forward,
        "ViewUniform",
        size_of::<ViewUniform>(),
        &[
            ("clip_from_world", offset_of!(ViewUniform, clip_from_world)),
            ("view_from_world", offset_of!(ViewUniform, view_from_world)),
            ("clip_from_view", offset_of!(ViewUniform, clip_from_view)),
            ("world_from_clip", offset_of!(ViewUniform, world_from_clip)),
            ("prev_clip_from_world", offset_of!(ViewUniform, prev_clip_from_world)),
            ("camera_position", offset_of!(ViewUniform, camera_position)),
            ("viewport", offset_of!(ViewUniform, viewport)),
            ("params", offset_of!(ViewUniform, params)),
            ("env_from_world", offset_of!(ViewUniform, env_from_world)),
            ("sky_from_world", offset_of!(ViewUniform, sky_from_world)),
            ("environment", offset_of!(ViewUniform, environment)),
            ("rays", offset_of!(ViewUniform, rays)),
            ("light_count", offset_of!(ViewUniform, light_count)),
            ("shading_model", offset_of!(ViewUniform, shading_model)),
            ("directional_count", offset_of!(ViewUniform, directional_count)),
            ("directional", offset_of!(ViewUniform, directional)),
        ],
    );
    offsets(
        &forward,
        "GpuDirectionalLight",
        size_of::<GpuDirectionalLight>(),
        &[
            ("direction", offset_of!(GpuDirectionalLight, direction)),
            ("color", offset_of!(GpuDirectionalLight, color)),
        ],
    );
    offsets(
        &forward,
        "GpuPointLight",
        size_of::<GpuPointLight>(),
        &[
            ("position_radius", offset_of!(GpuPointLight, position_radius)),
            ("color", offset_of!(GpuPointLight, color)),
            ("spot", offset_of!(GpuPointLight, spot)),
        ],
    );
    offsets(
        &forward,
        "GpuInstance",
        size_of::<GpuInstance>(),
        &[
            ("world_from_local", offset_of!(GpuInstance, world_from_local)),
            ("normal_from_local", offset_of!(GpuInstance, normal_from_local)),
        ],
    );
    offsets(
        &forward,
        "GpuMaterial",
        size_of::<GpuMaterial>(),
        &[
            ("base_color", offset_of!(GpuMaterial, base_color)),
            ("shininess", offset_of!(GpuMaterial, shininess)),
            ("specular", offset_of!(GpuMaterial, specular)),
            ("shading_model", offset_of!(GpuMaterial, shading_model)),
            ("has_texture", offset_of!(GpuMaterial, has_texture)),
            ("metallic", offset_of!(GpuMaterial, metallic)),
            ("roughness", offset_of!(GpuMaterial, roughness)),
            ("has_metallic_roughness_texture", offset_of!(GpuMaterial, has_metallic_roughness_texture)),
            ("normal_scale", offset_of!(GpuMaterial, normal_scale)),
            ("emissive", offset_of!(GpuMaterial, emissive)),
            ("occlusion_strength", offset_of!(GpuMaterial, occlusion_strength)),
            ("has_normal_texture", offset_of!(GpuMaterial, has_normal_texture)),
            ("has_occlusion_texture", offset_of!(GpuMaterial, has_occlusion_texture)),
            ("has_emissive_texture", offset_of!(GpuMaterial, has_emissive_texture)),
            ("alpha_cutoff", offset_of!(GpuMaterial, alpha_cutoff)),
            ("texture_uv", offset_of!(GpuMaterial, texture_uv)),
        ],
    );
    offsets(
        &forward,
        "GpuTextureUv",
        size_of::<GpuTextureUv>(),
        &[("row0", offset_of!(GpuTextureUv, row0)), ("row1", offset_of!(GpuTextureUv, row1))],
    );
    offsets(
        &validate("cluster_build.wgsl"),
        "ClusterCounters",
        size_of::<GpuClusterCounters>(),
        &[
            ("total_entries", offset_of!(GpuClusterCounters, total_entries)),
            ("dropped_pairs", offset_of!(GpuClusterCounters, dropped_pairs)),
            ("clusters_overflowed", offset_of!(GpuClusterCounters, clusters_overflowed)),
            ("max_count", offset_of!(GpuClusterCounters, max_count)),
            ("non_empty", offset_of!(GpuClusterCounters, non_empty)),
            ("tile_entries", offset_of!(GpuClusterCounters, tile_entries)),
            ("max_tile_lights", offset_of!(GpuClusterCounters, max_tile_lights)),
            ("coarse_entries", offset_of!(GpuClusterCounters, coarse_entries)),
            ("fallback_clusters", offset_of!(GpuClusterCounters, fallback_clusters)),
        ],
    );
    offsets(
        &validate("cluster_build.wgsl"),
        "GpuClusterBounds",
        size_of::<GpuClusterBounds>(),
        &[
            ("aabb_min", offset_of!(GpuClusterBounds, aabb_min)),
            ("aabb_max", offset_of!(GpuClusterBounds, aabb_max)),
            ("planes", offset_of!(GpuClusterBounds, planes)),
        ],
    );
    offsets(
        &validate("cluster_build.wgsl"),
        "ClusterParams",
        size_of::<GpuClusterParams>(),
        &[
            ("dims", offset_of!(GpuClusterParams, dims)),
            ("viewport", offset_of!(GpuClusterParams, viewport)),
            ("light_count", offset_of!(GpuClusterParams, light_count)),
            ("cap", offset_of!(GpuClusterParams, cap)),
            ("cull_test", offset_of!(GpuClusterParams, cull_test)),
            ("index_capacity", offset_of!(GpuClusterParams, index_capacity)),
            ("slicing", offset_of!(GpuClusterParams, slicing)),
            ("log_far_over_near", offset_of!(GpuClusterParams, log_far_over_near)),
            ("tile_index_capacity", offset_of!(GpuClusterParams, tile_index_capacity)),
            ("tile_chunks", offset_of!(GpuClusterParams, tile_chunks)),
            ("coarse_dims", offset_of!(GpuClusterParams, coarse_dims)),
            ("coarse_index_capacity", offset_of!(GpuClusterParams, coarse_index_capacity)),
            ("coarse_span", offset_of!(GpuClusterParams, coarse_span)),
            ("depth_bounds", offset_of!(GpuClusterParams, depth_bounds)),
            ("refine_blocks_x", offset_of!(GpuClusterParams, refine_blocks_x)),
            ("refine_blocks_y", offset_of!(GpuClusterParams, refine_blocks_y)),
            ("refined_first", offset_of!(GpuClusterParams, refined_first)),
            ("frustum", offset_of!(GpuClusterParams, frustum)),
            ("light_chunks", offset_of!(GpuClusterParams, light_chunks)),
            ("from_lights", offset_of!(GpuClusterParams, from_lights)),
            ("loop_limit", offset_of!(GpuClusterParams, loop_limit)),
            ("view_from_world", offset_of!(GpuClusterParams, view_from_world)),
        ],
    );
}

#[test]
fn constants_come_from_rust() {
    let code = compose("forward.wgsl").unwrap();
    for (name, value) in manylight_render::gpu_types::shared_u32_constants() {
        assert!(code.contains(&format!("const {name}: u32 = {value}u;")), "{name}");
    }
    let build = compose("cluster_build.wgsl").unwrap();
    for (name, value) in manylight_render::gpu_types::shared_f32_constants() {
        assert!(build.contains(&format!("const {name}: f32 = {value:?};")), "{name}");
        // Defined once: from Rust, never again in a shader.
        assert_eq!(build.matches(&format!("const {name}:")).count(), 1, "{name}");
    }
}

/// Every entry point of every shader also goes through naga's SPIR-V backend (what wgpu runs
/// for Vulkan), with each value of the `NORMAL_CODEC` override the passes use, so a backend
/// failure shows up without a GPU. (naga 30's backend panicked with "Expression … is not
/// cached" on a struct field passed as `ptr<function, …>`; validation had accepted it.)
#[test]
fn every_entry_point_compiles_to_spirv() {
    let codecs: Vec<f64> =
        manylight_core::codec::NormalCodec::ALL.iter().map(|c| c.gpu_id() as f64).collect();
    let composed = SOURCES.iter().flat_map(|(path, _)| {
        // A shader that reads or writes the G-buffer once per layout, the others once.
        let plain = compose(path).unwrap();
        GBUFFER_CHOICES.into_iter().filter_map(move |gbuffer| {
            let defs = ShaderDefs { gbuffer, ..Default::default() };
            (gbuffer.is_none() || compose_with(path, defs).unwrap() != plain).then_some((*path, defs))
        })
    });
    for (path, defs) in composed {
        let module = validate_with(path, defs);
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{path}: {e}"));
        let declares = |name: &str| module.overrides.iter().any(|(_, o)| o.name.as_deref() == Some(name));
        let mut variants: Vec<naga::back::PipelineConstants> = if declares("NORMAL_CODEC") {
            codecs.iter().map(|&c| [("NORMAL_CODEC".to_string(), c)].into_iter().collect()).collect()
        } else {
            vec![Default::default()]
        };
        // Mesh passes: every surface variant's constants (no texture, each slot alone, all five;
        // masked or not) on top of each codec's.
        if declares("ALPHA_MASK") {
            let texture_sets = [0u8, 1, 2, 4, 8, 16, 31];
            variants = variants
                .iter()
                .flat_map(|base| {
                    texture_sets.iter().flat_map(move |&textures| {
                        [false, true].map(|alpha_mask| {
                            let v = SurfaceVariant { alpha_mask, textures, ..Default::default() };
                            let mut c = base.clone();
                            c.extend(v.constants().map(|(name, value)| (name.to_string(), value)));
                            c
                        })
                    })
                })
                .collect();
        }
        for constants in &variants {
            for ep in &module.entry_points {
                let (module, info) = naga::back::pipeline_constants::process_overrides(
                    &module,
                    &info,
                    Some((ep.stage, &ep.name)),
                    constants,
                )
                .unwrap_or_else(|e| panic!("{path} {defs:?} {}: {e}", ep.name));
                let options = naga::back::spv::Options::default();
                let pipeline =
                    naga::back::spv::PipelineOptions { shader_stage: ep.stage, entry_point: ep.name.clone() };
                // naga's backend may panic rather than return an error: name the shader either way.
                let written = std::panic::catch_unwind(|| {
                    naga::back::spv::write_vec(&module, &info, &options, Some(&pipeline))
                });
                match written {
                    Ok(Ok(_)) => {}
                    Ok(Err(e)) => panic!("{path} {defs:?} {} {constants:?}: {e}", ep.name),
                    Err(_) => {
                        panic!("{path} {defs:?} {} {constants:?}: naga's SPIR-V backend panicked", ep.name)
                    }
                }
            }
        }
    }
}

/// Whether naga's view of a bound global variable is what its Rust declaration says.
fn kind_matches(kind: BindingKind, module: &naga::Module, var: &naga::GlobalVariable) -> bool {
    use naga::{AddressSpace, ImageClass, ImageDimension, ScalarKind, TypeInner};
    match (kind, var.space, &module.types[var.ty].inner) {
        (BindingKind::Uniform, AddressSpace::Uniform, _) => true,
        (BindingKind::Storage { read_only }, AddressSpace::Storage { access }, _) => {
            read_only != access.contains(naga::StorageAccess::STORE)
        }
        (
            BindingKind::Texture(sample_type),
            AddressSpace::Handle,
            TypeInner::Image { dim, arrayed, class },
        ) => {
            *dim == ImageDimension::D2
                && !arrayed
                && match (sample_type, class) {
                    (wgpu::TextureSampleType::Float { .. }, ImageClass::Sampled { kind, multi }) => {
                        *kind == ScalarKind::Float && !multi
                    }
                    (wgpu::TextureSampleType::Uint, ImageClass::Sampled { kind, multi }) => {
                        *kind == ScalarKind::Uint && !multi
                    }
                    (wgpu::TextureSampleType::Sint, ImageClass::Sampled { kind, multi }) => {
                        *kind == ScalarKind::Sint && !multi
                    }
                    (wgpu::TextureSampleType::Depth, ImageClass::Depth { multi }) => !multi,
                    _ => false,
                }
        }
        (
            BindingKind::Cube(wgpu::TextureSampleType::Float { .. }),
            AddressSpace::Handle,
            TypeInner::Image { dim, arrayed, class: ImageClass::Sampled { kind, multi } },
        ) => *dim == ImageDimension::Cube && !arrayed && *kind == ScalarKind::Float && !multi,
        (
            BindingKind::StorageTexture(format),
            AddressSpace::Handle,
            TypeInner::Image { dim, arrayed, class: ImageClass::Storage { format: naga_format, access } },
        ) => {
            *dim == ImageDimension::D2
                && !arrayed
                && storage_format_matches(format, *naga_format)
                && *access == naga::StorageAccess::STORE
        }
        (
            BindingKind::StorageTextureArray(format),
            AddressSpace::Handle,
            TypeInner::Image { dim, arrayed, class: ImageClass::Storage { format: naga_format, access } },
        ) => {
            *dim == ImageDimension::D2
                && *arrayed
                && storage_format_matches(format, *naga_format)
                && *access == naga::StorageAccess::STORE
        }
        (BindingKind::Sampler(ty), AddressSpace::Handle, TypeInner::Sampler { comparison }) => {
            *comparison == (ty == wgpu::SamplerBindingType::Comparison)
        }
        _ => false,
    }
}

/// Whether a storage texture's WGSL format is the one its Rust declaration names.
fn storage_format_matches(format: wgpu::TextureFormat, naga_format: naga::StorageFormat) -> bool {
    matches!(
        (format, naga_format),
        (wgpu::TextureFormat::Rgba16Float, naga::StorageFormat::Rgba16Float)
            | (wgpu::TextureFormat::Rgba32Float, naga::StorageFormat::Rgba32Float)
    )
}

/// The stage of an entry point as wgpu names it.
fn stage_of(stage: naga::ShaderStage) -> wgpu::ShaderStages {
    match stage {
        naga::ShaderStage::Vertex => wgpu::ShaderStages::VERTEX,
        naga::ShaderStage::Fragment => wgpu::ShaderStages::FRAGMENT,
        naga::ShaderStage::Compute => wgpu::ShaderStages::COMPUTE,
        other => panic!("no shader of ours has a {other:?} stage"),
    }
}

/// What is wrong with the bindings that `module`'s entry points use (composed from `path` with
/// `defs`), against [`SHADER_BIND_GROUPS`]: a used binding with no row, no group or no
/// declared entry, another variable name, another kind, or a stage the entry does not list.
fn binding_mismatches(
    path: &str,
    defs: ShaderDefs,
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
) -> Vec<String> {
    let mut errors = Vec::new();
    for (index, entry_point) in module.entry_points.iter().enumerate() {
        let uses = info.get_entry_point(index);
        let used: Vec<_> = module
            .global_variables
            .iter()
            .filter(|(handle, var)| var.binding.is_some() && !uses[*handle].is_empty())
            .collect();
        if used.is_empty() {
            continue;
        }
        let at = format!("{path} `{}` ({defs:?})", entry_point.name);
        let Some(row) = shader_bind_groups(path, &[&entry_point.name]) else {
            errors.push(format!("{at}: binds resources but has no row in SHADER_BIND_GROUPS"));
            continue;
        };
        for (_, var) in used {
            let (group, binding) = var.binding.as_ref().map(|b| (b.group, b.binding)).unwrap_or_default();
            let name = var.name.as_deref().unwrap_or("?");
            let here = format!("{at}: `{name}` @group({group}) @binding({binding})");
            let Some(decl) = row.groups.get(group as usize) else {
                errors.push(format!("{here}: the row declares {} groups", row.groups.len()));
                continue;
            };
            let Some(entry) = decl.entries_for(defs).find(|e| e.binding == binding) else {
                errors.push(format!(
                    "{here}: `{}` declares no binding {binding} for these defines",
                    decl.label
                ));
                continue;
            };
            if entry.name != name {
                errors.push(format!("{here}: `{}` names it `{}`", decl.label, entry.name));
            }
            if !kind_matches(entry.kind, module, var) {
                errors.push(format!("{here}: `{}` declares {:?}", decl.label, entry.kind));
            }
            let stage = stage_of(entry_point.stage);
            if !entry.visibility.contains(stage) {
                errors.push(format!(
                    "{here}: `{}` makes it visible to {:?}, not {stage:?}",
                    decl.label, entry.visibility
                ));
            }
        }
    }
    errors
}

/// Every `@group`/`@binding` an entry point of a library shader uses, in every composition, is
/// what the Rust declaration of that group says (the layout and the bind groups of its passes
/// come from that declaration): same binding number, variable name, kind and a visibility
/// that includes the entry point's stage. Every row of the table names entry points that exist.
#[test]
fn every_binding_matches_its_rust_declaration() {
    let mut errors = Vec::new();
    let mut entry_points = std::collections::HashSet::new();
    for (path, _) in SOURCES.iter().filter(|(path, _)| !path.contains('/')) {
        for defs in all_defs() {
            let code = compose_with(path, defs).unwrap_or_else(|e| panic!("{path}: {e}"));
            let module = naga::front::wgsl::parse_str(&code).unwrap_or_else(|e| panic!("{path}: {e}"));
            let info = naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{path}: {e}"));
            errors.extend(binding_mismatches(path, defs, &module, &info));
            entry_points.extend(module.entry_points.iter().map(|e| (path.to_string(), e.name.clone())));
        }
    }
    for row in SHADER_BIND_GROUPS {
        assert!(SOURCES.iter().any(|(path, _)| *path == row.shader), "{}: no such shader", row.shader);
        for name in row.entry_points {
            if !entry_points.contains(&(row.shader.to_string(), name.to_string())) {
                errors.push(format!("{} has no entry point `{name}`", row.shader));
            }
        }
    }
    assert!(errors.is_empty(), "{} binding mismatches:\n{}", errors.len(), errors.join("\n"));
}

/// Declaration labels are unique (a pipeline's layouts are checked against the table by label),
/// and no group declares a binding number twice.
#[test]
fn bind_group_declarations_are_unique() {
    let mut labels = std::collections::HashSet::new();
    for row in SHADER_BIND_GROUPS {
        for decl in row.groups {
            let first = labels.insert(decl.label);
            let same = SHADER_BIND_GROUPS.iter().flat_map(|r| r.groups).find(|d| d.label == decl.label);
            assert!(
                first || same.is_some_and(|d| std::ptr::eq(*d, *decl)),
                "two declarations named {}",
                decl.label
            );
            for (i, a) in decl.entries.iter().enumerate() {
                for b in &decl.entries[i + 1..] {
                    // Entries of different G-buffer layouts never meet in one layout.
                    let exclusive = matches!((a.presence, b.presence), (Presence::GBuffer(x), Presence::GBuffer(y)) if x != y);
                    assert!(
                        a.binding != b.binding || exclusive,
                        "{}: binding {} twice",
                        decl.label,
                        a.binding
                    );
                }
            }
        }
    }
}

/// The G-buffer targets of each layout (the G-buffer pass's colour targets, in order) are the
/// textures of [`GBUFFER_READ_GROUP`] for that layout, in order, with a sample type their format
/// can be read as; then depth and the clear colour.
#[test]
fn gbuffer_targets_are_the_read_group_in_order() {
    use manylight_render::layouts::GBUFFER_READ_GROUP;
    use manylight_render::passes::gbuffer_layout::targets;
    for layout in [GBufferLayout::Full, GBufferLayout::Packed, GBufferLayout::Compact] {
        let entries: Vec<_> =
            GBUFFER_READ_GROUP.entries_for(ShaderDefs::default().with_gbuffer(layout)).collect();
        let names: Vec<&str> = entries.iter().map(|e| e.name).collect();
        let mut expected: Vec<&str> = targets(layout).iter().map(|t| t.read.name).collect();
        expected.extend(["gb_depth", "clear_color"]);
        assert_eq!(names, expected, "{layout:?}");
        for t in targets(layout) {
            let uint = t.format == wgpu::TextureFormat::Rgba32Uint;
            let BindingKind::Texture(sample_type) = t.read.kind else { panic!("{}: not a texture", t.name) };
            assert_eq!(sample_type == wgpu::TextureSampleType::Uint, uint, "{layout:?} {}", t.name);
        }
    }
}
