//! What `bench` does: loads the scene, checks the most lights it sweeps, turns the command line
//! into a sweep for the `bench` module, and writes its CSV to `--out` and stdout.

use super::shared::{check_lights, scene_name};
use crate::args::BenchArgs;
use crate::{bench, plot};
use anyhow::{Context, Result};

/// `bench`: sweeps the pipelines, light counts, G-buffer layouts and shadow settings of the
/// command line and writes the timings as CSV (and figures with `--plot`).
pub(crate) fn run(args: BenchArgs) -> Result<()> {
    let scene = args.clusters.load(&args.scene)?;
    let most = args.lights.iter().copied().max().unwrap_or(0);
    check_lights(scene.lights.len().saturating_add(most), "--lights")?;
    let sweep = bench::Sweep {
        pipelines: args.pipelines,
        lights: args.lights,
        size: args.size,
        warmup: args.warmup,
        frames: args.frames.max(1),
        naive_max_lights: args.naive_max_lights,
        culling_efficiency: args.culling_efficiency,
        oracle: args.oracle,
        shell_lattice: args.scene == "sphere-shell",
        gbuffers: args.gbuffers,
        shadows: args.shadows,
        shadow_oracle: args.shadow_oracle,
        settings: manylight_render::FrameSettings {
            render: manylight_render::RenderSettings {
                clusters: args.clusters.settings(&args.scene),
                gbuffer: args.clusters.gbuffer,
                normal_codec: args.clusters.normal_codec,
                shading: args.shading,
                shadows: args.shadow.settings(manylight_render::ShadowMethod::Maps)?,
                ..Default::default()
            },
            ..Default::default()
        },
    };
    let csv = bench::run(&scene, &scene_name(&args.scene), &sweep)?;
    if let Some(parent) = args.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
    }
    std::fs::write(&args.out, &csv).with_context(|| format!("cannot write {}", args.out.display()))?;
    print!("{csv}");
    eprintln!("wrote {}", args.out.display());
    if let Some(dir) = &args.plot {
        for figure in plot::figures(&csv, dir)? {
            eprintln!("wrote {}", figure.display());
        }
    }
    Ok(())
}
