//! What several commands share: the light limit every rendering command checks first, and,
//! for the measuring commands, the scene's name in their tables, the settings they start from
//! and where their CSV and figures go.

use crate::args::ClusterArgs;
use crate::plot;
use anyhow::{Context, Result};

/// Refuses `count` lights — all the lights a command would create, named by `flags` — past the
/// light limit of the adapter the command renders with, or past the memory available, before
/// any light is created.
pub(crate) fn check_lights(count: usize, flags: &str) -> Result<()> {
    use manylight_core::light_count::{APP_BYTES_PER_LIGHT, check_light_count};
    let limit = manylight_render::context::adapter_light_limit()?;
    check_light_count(count, limit, APP_BYTES_PER_LIGHT).with_context(|| flags.to_string())
}

/// The scene's name in tables and figure titles: the preset's name, or the file's stem.
pub(crate) fn scene_name(spec: &str) -> String {
    match spec {
        "default" | "sphere-shell" => spec.to_string(),
        path => std::path::Path::new(path)
            .file_stem()
            .map_or_else(|| path.to_string(), |s| s.to_string_lossy().into_owned()),
    }
}

/// Writes `csv` as `<dir>/<name>.csv` and its figures beside it; prints what it wrote.
pub(crate) fn write_plots(dir: &std::path::Path, name: &str, csv: &str) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let path = dir.join(format!("{name}.csv"));
    std::fs::write(&path, csv).with_context(|| format!("cannot write {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    for figure in plot::figures_named(csv, dir, Some(name))? {
        eprintln!("wrote {}", figure.display());
    }
    Ok(())
}

/// The settings the measuring subcommands (`report`, `rangeless-lights`, `post`, `views`)
/// start from: the defaults with the command line's cluster settings for `scene`.
pub(crate) fn measure_base(clusters: &ClusterArgs, scene: &str) -> manylight_render::FrameSettings {
    manylight_render::FrameSettings {
        render: manylight_render::RenderSettings { clusters: clusters.settings(scene), ..Default::default() },
        ..Default::default()
    }
}
