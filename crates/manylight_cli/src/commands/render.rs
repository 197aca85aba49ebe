//! What `render` does: loads the scene, picks its camera, adds the lights of the command line,
//! takes the measurements its flags ask for, draws the frames through the app and writes the
//! last one as PNG (and its statistics as JSON).

mod measure;

use super::headless::{CameraEnvironment, Extras, render_scene};
use super::shared::check_lights;
use crate::args::RenderArgs;
use crate::camera_spec::CameraSpec;
use anyhow::{Context, Result, bail};
use manylight_app::RenderSettings;
use manylight_app::headless::save_png;
use manylight_scene::Scene;
use measure::{
    measure_culling_efficiency, measure_oracle, measure_shadow_accuracy, measured_snapshot, render_stats_json,
};

/// `render`: draws the scene through the app and writes the last frame as PNG, after the
/// measurements of the flags that ask for them.
pub(crate) fn run(args: RenderArgs) -> Result<()> {
    let mut scene = args.clusters.load(&args.scene)?;
    select_camera(&mut scene, &args.camera)?;
    let lit = add_render_lights(&mut scene, &args)?;
    let ambient = args.ambient.unwrap_or(if lit.unlit { 0.2 } else { RenderSettings::default().ambient });
    let shadow_settings = args.shadow.settings(args.shadows.method())?;
    let measured = measured_snapshot(&args, &scene, lit.rig, shadow_settings)?;
    let culling = match &measured {
        Some(snap) if args.culling_efficiency => Some(measure_culling_efficiency(snap.clone())?),
        _ => None,
    };
    let shadow_accuracy = match &measured {
        Some(snap) if args.shadow_oracle => {
            let a = measure_shadow_accuracy(&scene, snap.clone())?;
            if let Some(path) = &args.shadow_reference {
                save_png(&a.reference, path).map_err(anyhow::Error::msg)?;
                println!("wrote the shadow reference to {}", path.display());
            }
            Some(a)
        }
        _ => None,
    };
    let oracle = match measured {
        Some(snap) if args.oracle => Some(measure_oracle(snap, args.pipeline)?),
        _ => None,
    };
    let settings = app_settings(&args, ambient, shadow_settings);
    let frames = if args.post.motion_blur { args.frames.max(2) } else { args.frames };
    let extras = render_extras(&args)?;
    let (image, stats) = render_scene(scene, args.size, frames, lit.rig, args.seed, settings, extras)?;
    save_png(&image, &args.out).map_err(anyhow::Error::msg)?;
    if let Some(path) = &args.stats_json {
        let json = render_stats_json(&stats, oracle, shadow_accuracy.as_ref(), culling);
        let text = serde_json::to_string_pretty(&json)?;
        std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(r) = &stats.last {
        print_written(&args.out, r);
    }
    Ok(())
}

/// What `render` lights its scene with beyond the scene's own lights.
struct RenderLights {
    /// Animated rig lights the app spawns (`--lights`; none for the sphere-shell preset).
    rig: usize,
    /// The scene is unlit by itself: it brings no lights of its own (for the sphere-shell
    /// preset: its lattice is empty), so ambient light and studio lights default higher.
    unlit: bool,
}

/// Adds the sphere-shell preset's lattice and the studio lights to `scene`, after checking
/// every light the command creates against the adapter's light limit and the memory.
fn add_render_lights(scene: &mut Scene, args: &RenderArgs) -> Result<RenderLights> {
    // The sphere-shell preset is lit by its own lattice (`--lights`, default 100 000 of range
    // 0.3 just inside the radius-50 sphere), not by the animated rig.
    let shell = args.scene == "sphere-shell";
    let shell_lights = if shell { args.lights.unwrap_or(100_000) } else { 0 };
    // A scene lit only by directional lights is lit: studio lights are for scenes with none.
    let unlit = if shell {
        shell_lights == 0
    } else {
        scene.lights.is_empty() && scene.directional_lights.is_empty()
    };
    let lights = if shell { 0 } else { args.lights.unwrap_or(0) };
    let studio = args.studio_lights.unwrap_or(if unlit && args.lights.is_none() { 32 } else { 0 });
    let total = [scene.lights.len(), shell_lights, lights, studio].into_iter().fold(0, usize::saturating_add);
    check_lights(total, "--lights and --studio-lights (with the scene's own lights)")?;
    if shell {
        scene.lights = manylight_scene::sphere_shell_lights(
            shell_lights,
            manylight_scene::SHELL_RADIUS,
            manylight_scene::SHELL_LIGHT_RANGE,
            args.seed,
        )?;
    }
    let studio = manylight_scene::studio_lights(studio, scene.bounds())?;
    scene.lights.extend(studio);
    Ok(RenderLights { rig: lights, unlit })
}

/// Reorders or clears the scene's cameras, or puts an explicit one (`look-at:…`, `ortho:…`)
/// before them, so the chosen one comes first.
fn select_camera(scene: &mut Scene, choice: &str) -> Result<()> {
    let spec: CameraSpec = choice.parse()?;
    match spec {
        CameraSpec::Scene => {}
        CameraSpec::Fit => scene.cameras.clear(),
        CameraSpec::Index(i) => {
            if i >= scene.cameras.len() {
                bail!("--camera {i}: the scene has {} cameras", scene.cameras.len());
            }
            scene.cameras.swap(0, i);
        }
        // An explicit placement goes first, so it is the one the app renders through.
        CameraSpec::LookAt { .. } | CameraSpec::Ortho { .. } => {
            if let Some(camera) = spec.explicit_camera(scene.bounds()) {
                scene.cameras.insert(0, camera);
            }
        }
    }
    Ok(())
}

/// The app's settings for `render`, from the command line.
fn app_settings(
    args: &RenderArgs,
    ambient: f32,
    shadows: manylight_render::ShadowSettings,
) -> RenderSettings {
    RenderSettings {
        pipeline: args.pipeline,
        shading: args.shading,
        exposure: args.ev100.map_or(args.exposure, |ev100| manylight_app::Exposure { ev100 }.multiplier()),
        ambient,
        clusters: args.clusters.settings(&args.scene),
        gbuffer: args.clusters.gbuffer,
        normal_codec: args.clusters.normal_codec,
        shadows,
        ..RenderSettings::default()
    }
}

/// The post stages, environment, debug view and shadows `render` adds to the scene.
fn render_extras(args: &RenderArgs) -> Result<Extras> {
    let environment = match &args.environment.environment {
        Some(path) => {
            let budget = manylight_scene::EnvironmentBudget::default();
            let decoded = manylight_scene::load_environment(path, &budget).context("--environment")?;
            if decoded.clamped_texels > 0 {
                println!(
                    "{}: {} texels not finite, negative or above f16's range, clamped",
                    path.display(),
                    decoded.clamped_texels
                );
            }
            Some(CameraEnvironment {
                image: std::sync::Arc::new(decoded.image),
                intensity: args.environment.environment_intensity,
                skybox: args.environment.skybox,
            })
        }
        None => None,
    };
    Ok(Extras {
        bloom: args.post.bloom.then(|| manylight_app::Bloom {
            chain: args.post.bloom_chain,
            ..manylight_app::Bloom::default()
        }),
        motion_blur: args.post.motion_blur.then(manylight_app::MotionBlur::default),
        debug: manylight_app::DebugView::new(args.clusters.debug_view),
        shadows: args.shadows.casts(),
        environment,
    })
}

/// Prints what `render` wrote to `out`: the last frame's size, lights, instances and passes.
fn print_written(out: &std::path::Path, r: &manylight_render::FrameReport) {
    let passes: Vec<String> = r
        .passes
        .iter()
        .map(|p| match p.gpu_ms {
            Some(g) => format!("{} {:.2} ms", p.name, g),
            None => format!("{} (cpu {:.2} ms)", p.name, p.cpu_ms),
        })
        .collect();
    println!(
        "wrote {} ({}x{}, {} lights, {} instances): {}",
        out.display(),
        r.width,
        r.height,
        r.light_count,
        r.instance_count,
        passes.join(", ")
    );
}
