//! The `manylight` binary as a user runs it: `check` on every malformed file exits 1 with one
//! typed error naming the file (never a panic), on real assets exits 0; `render` writes the PNG
//! and the stats JSON; a short `soak` passes in a window. Runs on a real device (lavapipe in CI),
//! one command at a time.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Mutex;

static GPU: Mutex<()> = Mutex::new(());

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn manylight(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_manylight")).args(args).output().expect("the binary runs")
}

fn bad_files() -> Vec<PathBuf> {
    let dir = root().join("tests/data/bad_gltf");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "gltf" || e == "glb"))
        .collect();
    files.sort();
    files
}

#[test]
fn check_rejects_every_malformed_file_with_a_typed_error() {
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let files = bad_files();
    assert!(files.len() >= 20, "expected the malformed-glTF corpus, found {}", files.len());
    for file in files {
        let out = manylight(&["check", file.to_str().expect("utf-8 path")]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{}: exit {:?}\n{stderr}", file.display(), out.status);
        let name = file.file_name().and_then(|n| n.to_str()).expect("name");
        let line = stderr.lines().find(|l| l.starts_with("error: ")).unwrap_or_else(|| {
            panic!("{}: no `error:` line in\n{stderr}", file.display());
        });
        assert!(line.contains(name), "{}: the error does not name the file: {line}", file.display());
        assert!(!stderr.contains("panicked"), "{}: panicked\n{stderr}", file.display());
    }
}

#[test]
fn check_accepts_real_assets() {
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let assets = root().join("assets");
    for rel in
        ["DamagedHelmet/DamagedHelmet.glb", "CornellBox/CornellBox.gltf", "BoxTextured/BoxTextured.gltf"]
    {
        let path = assets.join(rel);
        let out = manylight(&["check", path.to_str().expect("utf-8 path")]);
        assert!(out.status.success(), "{rel}: {}", String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stdout).starts_with("ok: "));
    }
}

#[test]
fn render_writes_png_and_stats_json() {
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let dir = root().join("target/cli-tests");
    std::fs::create_dir_all(&dir).expect("mkdir");
    let png = dir.join("render.png");
    let json = dir.join("render.json");
    let out = manylight(&[
        "render",
        "--scene",
        "default",
        "--lights",
        "16",
        "--size",
        "96x64",
        "--frames",
        "2",
        "--out",
        png.to_str().expect("utf-8"),
        "--stats-json",
        json.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&png).expect("png").to_rgba8();
    assert_eq!(img.dimensions(), (96, 64));
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("valid");
    let last = &stats["last_frame"];
    let names: Vec<&str> =
        last["passes"].as_array().expect("passes").iter().map(|p| p["name"].as_str().unwrap_or("")).collect();
    assert_eq!(
        names,
        ["depth_prepass", "cluster_depth", "cluster_build", "light_refine", "clustered_forward", "tonemap"]
    );
    assert!(last["clusters"]["total_entries"].as_u64().is_some_and(|n| n > 0));
    assert_eq!(last["clusters"]["dropped_pairs"].as_u64(), Some(0));
    assert!(last["passes"][0]["gpu_ms"].is_number());
    assert!(last["passes"][0]["cpu_ms"].is_number());
    assert!(last["frame_cpu_ms"].is_number());
    assert_eq!(last["light_count"].as_u64(), Some(16 + 6));
    assert_eq!(last["nonfinite_pixels"].as_u64(), Some(0));
    assert_eq!(last["invalid_lights"].as_u64(), Some(0));
    assert_eq!(
        last["transient_bytes"].as_u64(),
        Some(96 * 64 * (8 + 4 + 4)),
        "rgba16f hdr + depth + r32f shading distance"
    );
    assert_eq!(stats["frames_rendered"].as_u64(), Some(2));
}

/// `--environment` lights the scene from a bundled panorama: the skybox pass runs, the
/// environment report says one panorama was prefiltered, and the background is the sky.
#[test]
fn render_takes_an_environment() {
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let dir = root().join("target/cli-tests");
    std::fs::create_dir_all(&dir).expect("mkdir");
    let png = dir.join("environment.png");
    let json = dir.join("environment.json");
    let sky = root().join("assets/environments/venice_sunset.hdr");
    let spheres = root().join("assets/MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.gltf");
    let out = manylight(&[
        "render",
        "--scene",
        spheres.to_str().expect("utf-8"),
        "--environment",
        sky.to_str().expect("utf-8"),
        "--studio-lights",
        "0",
        "--size",
        "96x96",
        "--out",
        png.to_str().expect("utf-8"),
        "--stats-json",
        json.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("valid");
    let last = &stats["last_frame"];
    let names: Vec<&str> =
        last["passes"].as_array().expect("passes").iter().map(|p| p["name"].as_str().unwrap_or("")).collect();
    assert!(names.contains(&"skybox"), "{names:?}");
    assert_eq!(last["environment"]["prefiltered"].as_u64(), Some(1));
    assert_eq!(last["nonfinite_pixels"].as_u64(), Some(0));
    let img = image::open(&png).expect("png").to_rgba8();
    let corner = img.get_pixel(1, 1);
    assert!(corner[0] > 60 && corner[2] > 60, "the corner shows the sky: {corner:?}");
}

#[test]
fn bad_arguments_are_refused_with_a_message() {
    for args in [
        &["render", "--out", "x.png", "--size", "0x10"][..],
        &["render", "--out", "x.png", "--pipeline", "magic"],
        &["render", "--out", "x.png", "--scene", "/nonexistent/scene.gltf"],
        &["check", "/nonexistent/file.glb"],
        &["render", "--out", "x.png", "--environment", "/nonexistent/sky.hdr"],
        &["render", "--out", "x.png", "--environment", "Cargo.toml"],
        &["render", "--out", "x.png", "--environment", "sky.hdr", "--skybox", "maybe"],
        &["render", "--out", "x.png", "--environment", "sky.hdr", "--environment-intensity", "nan"],
        &["render", "--out", "x.png", "--skybox", "on"],
        &["compare", "Cargo.toml", "Cargo.toml"],
        &["soak", "--frames", "100", "--warmup", "100"],
        &["soak", "--sizes", "0x10"],
    ] {
        let out = manylight(args);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert_ne!(out.status.code(), Some(101), "{args:?} panicked");
        assert!(!out.stderr.is_empty(), "{args:?} said nothing");
    }
}

/// A short soak in a window: every setting changes several times in 400 frames (sizes every
/// 50, post stages every 20, debug views every 20, light counts every 100), and it must pass.
/// Memory growth is measured after frame 300, once every debug view and post stage has been
/// used (and its pipelines compiled) at least once.
/// The command starts its own Xvfb when no display is set; without either the test says so
/// loudly and passes, unless `CI=true`, where it fails.
#[test]
fn a_short_soak_passes() {
    let has_display = manylight_app::window::xvfb::has_display();
    if !has_display && Command::new("Xvfb").arg("-help").output().is_err() {
        let ci = std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
        assert!(!ci, "CI=true but no display and no Xvfb: install Xvfb (package xvfb)");
        eprintln!("\n\n*** SKIPPING the soak test: no DISPLAY and no Xvfb. Install Xvfb to run it. ***\n");
        return;
    }
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let csv = root().join("target/cli-tests/soak.csv");
    let _ = std::fs::remove_file(&csv);
    let started = std::time::Instant::now();
    let out = manylight(&[
        "soak",
        "--frames",
        "400",
        "--warmup",
        "300",
        "--lights",
        "1024,512",
        "--lights-every",
        "100",
        "--post-every",
        "20",
        "--debug-every",
        "20",
        "--csv",
        csv.to_str().expect("utf-8"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("soak test: {:.1?}: {stdout}", started.elapsed());
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let summary =
        stdout.lines().find(|l| l.starts_with("soak ")).unwrap_or_else(|| panic!("no summary:\n{stdout}"));
    assert!(summary.starts_with("soak PASS: 400 frames"), "{summary}");
    assert!(summary.contains("0 render errors; 0 non-finite pixels"), "{summary}");
    let text = std::fs::read_to_string(&csv).expect("csv");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + 4, "header + a sample every 100 frames:\n{text}");
    assert!(lines[0].starts_with("frame,seconds,frame_ms,rss_kib,"), "{}", lines[0]);
    for (line, frame) in lines[1..].iter().zip(["100,", "200,", "300,", "400,"]) {
        assert!(line.starts_with(frame), "{line}");
        assert!(line.ends_with(",0"), "non-finite pixels: {line}");
    }
}

#[test]
fn bench_writes_a_csv_row_per_configuration() {
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let csv = root().join("target/cli-tests/bench.csv");
    let plots = root().join("target/cli-tests/bench-plots");
    let _ = std::fs::remove_dir_all(&plots);
    let out = manylight(&[
        "bench",
        "--lights",
        "8,32",
        "--size",
        "96x64",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--culling-efficiency",
        "--out",
        csv.to_str().expect("utf-8"),
        "--plot",
        plots.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).expect("csv");
    assert_figures(&plots, &["bench_frame_time", "bench_culling_ratio", "bench_passes", "bench_memory"]);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines.len(),
        1 + 10,
        "header + (3 pipelines + deferred x 2 layouts) x 2 light counts:\n{text}"
    );
    assert!(lines[0].starts_with("adapter,scene,pipeline,gbuffer,"), "{}", lines[0]);
    assert!(lines[1..].iter().all(|l| l.contains(",\"default\",")), "{text}");
    assert!(lines.iter().any(|l| l.contains(",clustered-deferred,compact,28,32,")), "{text}");
    let header: Vec<&str> = lines[0].split(',').collect();
    let column =
        |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    // The adapter name is quoted and may hold commas: count columns from the end.
    let field = |line: &str, name: &str| -> String {
        let fields: Vec<&str> = line.split(',').collect();
        fields[fields.len() - (header.len() - column(name))].to_string()
    };
    let clustered = lines.iter().find(|l| l.contains(",clustered-forward,,,32,")).expect("row");
    let culling = field(clustered, "culling_ratio");
    assert!(culling.parse::<f64>().is_ok_and(|r| r >= 1.0), "culling ratio `{culling}`");
    // 96×64 rgba16f HDR + depth32f + r32f shading distance (per-cluster depth bounds) = 96 KiB
    // of frame textures; cluster buffers exist.
    let textures = field(clustered, "transient_mib");
    assert!(
        textures.parse::<f64>().is_ok_and(|m| (m - 96.0 * 64.0 * 16.0 / 1048576.0).abs() < 0.01),
        "{textures}"
    );
    assert!(field(clustered, "cluster_buffer_mib").parse::<f64>().is_ok_and(|m| m > 0.0));
}

/// The figures `names` exist in `dir` as PNGs with something drawn on them.
fn assert_figures(dir: &Path, names: &[&str]) {
    for name in names {
        let path = dir.join(format!("{name}.png"));
        let img = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8();
        assert!(img.width() >= 1000 && img.height() >= 400, "{}: {:?}", path.display(), img.dimensions());
        let drawn = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        assert!(drawn > 5000, "{}: only {drawn} pixels drawn", path.display());
    }
}

#[test]
fn report_writes_csv_and_figures() {
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let plots = root().join("target/cli-tests/report-plots");
    let _ = std::fs::remove_dir_all(&plots);
    let out = manylight(&[
        "report",
        "--lights",
        "8",
        "--size",
        "48x32",
        "--frames",
        "1",
        "--plot",
        plots.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let (markdown, rangeless) =
        stdout.split_once("Lights without a range").expect("the range-less lights table");
    let text = std::fs::read_to_string(plots.join("report.csv")).expect("report.csv");
    let rows: Vec<&str> = text.lines().collect();
    // The markdown table and the CSV hold the same configurations.
    let table_rows = markdown.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| pipeline")).count();
    assert_eq!(rows.len() - 1, table_rows, "{text}\n{markdown}");
    // The range-less table: one row per cut-off and the unbounded one, which equals its reference.
    let cut_rows: Vec<&str> =
        rangeless.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| cut")).collect();
    assert_eq!(cut_rows.len(), 6, "{rangeless}");
    assert!(cut_rows[5].starts_with("| unbounded | 10000.0 | 0.00000 | 0.00000 |"), "{rangeless}");
    assert!(rows[0].contains("flip_mean") && rows[0].contains("frame_ms_median"), "{}", rows[0]);
    assert!(rows[1].contains("naive forward (reference)"), "{}", rows[1]);
    assert_figures(&plots, &["report_accuracy_vs_time", "report_passes", "report_memory"]);
    // `plot` draws the same figures again from the CSV alone.
    let again = root().join("target/cli-tests/report-plots-again");
    let _ = std::fs::remove_dir_all(&again);
    let out = manylight(&[
        "plot",
        plots.join("report.csv").to_str().expect("utf-8"),
        "--out",
        again.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for name in ["report_accuracy_vs_time", "report_passes", "report_memory"] {
        let a = std::fs::read(plots.join(format!("{name}.png"))).expect("figure");
        let b = std::fs::read(again.join(format!("{name}.png"))).expect("figure again");
        assert!(a == b, "{name}: the figure drawn from the CSV differs from the one drawn with it");
    }
}

/// The shadow measurements: `render --shadow-oracle` prints and records the visibility error,
/// `bench --shadow-oracle` fills its CSV columns, `report --shadows` writes its section, CSV
/// and figures.
#[test]
fn shadow_measurements_come_out_of_render_bench_and_report() {
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let dir = root().join("target/cli-tests");
    std::fs::create_dir_all(&dir).expect("mkdir");
    let json = dir.join("shadows.json");
    let reference = dir.join("shadow_reference.png");
    let out = manylight(&[
        "render",
        "--lights",
        "8",
        "--size",
        "64x48",
        "--shadows",
        "on",
        "--shadow-oracle",
        "--shadow-reference",
        reference.to_str().expect("utf-8"),
        "--out",
        dir.join("shadows.png").to_str().expect("utf-8"),
        "--stats-json",
        json.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("shadow oracle: visibility error"));
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("valid");
    let error = stats["shadow_oracle"]["visibility_error"].as_f64().expect("visibility_error");
    assert!((0.0..0.1).contains(&error), "{error}");
    assert!(stats["shadow_oracle"]["contributing_pairs"].as_u64().is_some_and(|n| n > 0));
    assert!(stats["last_frame"]["shadows"]["maps_rendered"].as_u64().is_some_and(|n| n > 0));
    assert_eq!(image::open(&reference).expect("reference").to_rgba8().dimensions(), (64, 48));

    let csv = dir.join("shadows_bench.csv");
    let out = manylight(&[
        "bench",
        "--pipelines",
        "clustered-forward",
        "--lights",
        "8",
        "--size",
        "64x48",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--shadows",
        "off,on,rays",
        "--shadow-oracle",
        "--out",
        csv.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).expect("csv");
    let mut rows = csv::Reader::from_reader(text.as_bytes());
    let header = rows.headers().expect("header").clone();
    let at = |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no {name}"));
    let records: Vec<csv::StringRecord> = rows.records().map(|r| r.expect("row")).collect();
    assert_eq!(records.len(), 3, "{text}");
    let number = |r: &csv::StringRecord, name: &str| -> f64 {
        r[at(name)].parse().unwrap_or_else(|_| panic!("`{name}` is not a number in {text}"))
    };
    let errors: Vec<f64> = records.iter().map(|r| number(r, "visibility_error")).collect();
    assert!(errors.iter().all(|e| (0.0..=1.0).contains(e)), "{errors:?}");
    let shadows: Vec<&str> = records.iter().map(|r| &r[at("shadows")]).collect();
    assert_eq!(shadows, ["off", "maps", "rays"]);
    assert!(records[1][at("flip_vs_shadow_reference")].parse::<f64>().is_ok());
    // The shadow measures of every technique: the light error and, still, no flicker.
    for r in &records {
        assert!((0.0..1.0).contains(&number(r, "light_error")), "{text}");
        assert!((0.0..1e-4).contains(&number(r, "flicker")), "{text}");
    }
    assert!(number(&records[1], "light_error") < 0.02, "maps: {text}");
    // Rays are exact: every reached pair agrees with the oracle.
    assert_eq!(errors[2], 0.0, "rays: {text}");
    assert!(number(&records[2], "light_error") < 1e-3, "rays: {text}");

    let plots = dir.join("report-shadow-plots");
    let _ = std::fs::remove_dir_all(&plots);
    let out = manylight(&[
        "report",
        "--lights",
        "8",
        "--size",
        "48x32",
        "--frames",
        "1",
        "--shadows",
        "--plot",
        plots.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let (_, shadows) = stdout.split_once("## Shadows").expect("the shadow section");
    let table_rows = shadows.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| setting")).count();
    let text = std::fs::read_to_string(plots.join("report_shadows.csv")).expect("report_shadows.csv");
    assert_eq!(text.lines().count() - 1, table_rows, "{text}\n{shadows}");
    assert!(text.lines().nth(1).is_some_and(|l| l.contains("shadows off")), "{text}");
    // Shadow rays are a row of their own, exact: no pair on the wrong side.
    let mut report_rows = csv::Reader::from_reader(text.as_bytes());
    let header = report_rows.headers().expect("header").clone();
    let column = |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no {name}"));
    let rays: Vec<csv::StringRecord> = report_rows
        .records()
        .map(|r| r.expect("row"))
        .filter(|r| r.iter().any(|f| f.contains("rays (exact)")))
        .collect();
    assert_eq!(rays.len(), 2, "{text}");
    for r in &rays {
        assert_eq!(r[column("visibility_error")].parse::<f64>().expect("a number"), 0.0, "{text}");
        assert!(r[column("light_error")].parse::<f64>().is_ok_and(|e| (0.0..1e-3).contains(&e)), "{text}");
    }
    assert_figures(&plots, &["report_shadows_accuracy_vs_time", "report_shadows_passes"]);
}

/// A glTF scene lit only by a directional light (`tests/data/sun_only.gltf`: a floor, a cube
/// and a sun) is lit: `render` adds no studio lights to it, and `--shadow-oracle` measures it
/// (no point or spot light, so no pairs) instead of failing for want of clusters.
#[test]
fn a_scene_lit_only_by_the_sun_is_rendered_as_lit_and_measured() {
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let dir = root().join("target/cli-tests");
    std::fs::create_dir_all(&dir).expect("mkdir");
    let json = dir.join("sun_only.json");
    let scene = root().join("tests/data/sun_only.gltf");
    let out = manylight(&[
        "render",
        "--scene",
        scene.to_str().expect("utf-8"),
        "--size",
        "64x48",
        "--shadows",
        "on",
        "--shadow-oracle",
        "--out",
        dir.join("sun_only.png").to_str().expect("utf-8"),
        "--stats-json",
        json.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("the 1 directional light(s) are not measured"), "{stdout}");
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("valid");
    assert_eq!(stats["last_frame"]["light_count"].as_u64(), Some(0), "no studio lights were added");
    assert_eq!(stats["shadow_oracle"]["contributing_pairs"].as_u64(), Some(0));
    assert_eq!(stats["shadow_oracle"]["flip_vs_shadow_reference"].as_f64(), Some(0.0));
    let image = image::open(dir.join("sun_only.png")).expect("png").to_rgba8();
    let lit = image.pixels().filter(|p| p[0] > 64).count();
    assert!(lit > image.pixels().len() / 4, "the sun lights the floor: {lit} bright pixels");
}

/// Arguments that used to allocate before any limit was checked (`--lights 4294967295` aborted
/// on a 240 GB allocation, `--lights 18446744073709551615` panicked with "capacity overflow",
/// `--lights 10000000` reached 2.9 GB spawning entities past lavapipe's 2 796 202-light
/// buffer) or rendered a black image and exited 0 (`--exposure NaN`): each exits 1 or 2 with a
/// message naming the limit, without its resident memory reaching 256 MiB (what it would have
/// allocated is gigabytes).
#[test]
fn arguments_past_a_limit_exit_with_a_message_before_allocating() {
    let _gpu = GPU.lock().unwrap_or_else(|e| e.into_inner());
    let out = root().join("target/cli-tests/refused.png");
    let out = out.to_str().expect("utf-8 path");
    let cases: [(&[&str], &str); 9] = [
        (&["--lights", "4294967295"], "lights"),
        (&["--lights", "18446744073709551615"], "lights"),
        (&["--studio-lights", "4294967295"], "lights"),
        (&["--lights", "10000000"], "max_storage_buffer_binding_size"),
        (&["--scene", "sphere-shell", "--lights", "4294967295"], "lights"),
        (&["--exposure", "NaN"], "exposure"),
        (&["--ev100", "inf"], "ev100"),
        (&["--ambient", "-1"], "ambient"),
        (&["--exposure", "-2"], "exposure"),
    ];
    for (flags, named) in cases {
        let mut args = vec!["render", "--size", "64x32", "--out", out];
        args.extend_from_slice(flags);
        let run = run_watched(&args);
        let stderr = String::from_utf8_lossy(&run.output.stderr);
        let code = run.output.status.code();
        assert!(matches!(code, Some(1 | 2)), "{flags:?}: exit {:?}\n{stderr}", run.output.status);
        assert!(stderr.contains(named), "{flags:?}: the message does not name `{named}`:\n{stderr}");
        assert!(!stderr.contains("panicked") && !stderr.contains("memory allocation"), "{flags:?}: {stderr}");
        assert!(run.peak_rss < 256 << 20, "{flags:?}: resident memory reached {} MiB", run.peak_rss >> 20);
    }
}

/// A finished run of the binary with the largest resident set seen.
struct WatchedRun {
    output: Output,
    peak_rss: u64,
}

/// Runs the binary with `args`, reading its peak resident set (`VmHWM`) from `/proc` until it
/// exits (0 where `/proc` cannot be read). A run still going after 120 s fails, so a hang does
/// not stall the suite.
fn run_watched(args: &[&str]) -> WatchedRun {
    use std::process::Stdio;
    let start = std::time::Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let status_path = format!("/proc/{}/status", child.id());
    let mut peak_rss = 0u64;
    while child.try_wait().expect("wait").is_none() {
        if let Ok(status) = std::fs::read_to_string(&status_path)
            && let Some(kib) = status
                .lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        {
            peak_rss = peak_rss.max(kib * 1024);
        }
        assert!(start.elapsed().as_secs() < 120, "{args:?} still runs after 120 s");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let output = child.wait_with_output().expect("output");
    WatchedRun { output, peak_rss }
}
