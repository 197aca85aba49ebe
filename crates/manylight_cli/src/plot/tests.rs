//! The figures drawn from small CSVs of each command.

use super::*;

const BENCH: &str = "adapter,scene,pipeline,gbuffer,lights,width,height,frame_ms_median,forward_gpu_ms,\
    cluster_build_gpu_ms,cluster_build_gpu_trusted,culling_ratio,transient_mib,cluster_buffer_mib\n\
    \"llvmpipe (LLVM 15, 256 bits)\",default,naive,,16,96,64,40.5,38.0,,,,0.07,\n\
    \"llvmpipe (LLVM 15, 256 bits)\",default,clustered-forward,,16,96,64,12.0,,0.02,false,1.4,0.07,0.50\n\
    \"llvmpipe (LLVM 15, 256 bits)\",default,clustered-deferred,full,16,96,64,14.0,,0.02,false,1.5,0.20,0.50\n\
    \"llvmpipe (LLVM 15, 256 bits)\",default,clustered-forward,,64,96,64,20.0,,0.03,false,1.2,0.07,0.60\n";

#[test]
fn series_follow_the_csv() {
    let t = Table::parse(BENCH).expect("parses");
    let s = series_over_lights(&t, "frame_ms_median");
    assert_eq!(s.len(), 3);
    assert_eq!(s[0], ("naive".to_string(), vec![(16.0, 40.5)]));
    assert_eq!(s[1], ("clustered-forward".to_string(), vec![(16.0, 12.0), (64.0, 20.0)]));
    assert_eq!(s[2].0, "clustered-deferred, full G-buffer");
    let culling = series_over_lights(&t, "culling_ratio");
    assert_eq!(culling[0], ("clustered-forward".to_string(), vec![(16.0, 1.4), (64.0, 1.2)]));
    // Bars show the largest light count only.
    let bars = pass_bars(&t);
    assert_eq!(bars, vec![("clustered-forward".to_string(), vec![("cluster_build".to_string(), 0.03)])]);
    let memory = memory_bars(&t);
    assert_eq!(
        memory[0].1,
        vec![("frame textures".to_string(), 0.07), ("cluster buffers".to_string(), 0.60)]
    );
    assert_eq!(t.setting(), "default, 96×64, llvmpipe (LLVM 15, 256 bits)");
}

/// A CSV of 200 000 configurations at one light count would ask for a figure 8.8 million
/// pixels tall (and, with `u32` sizes, wrap past 2^32 at larger counts): refused, naming
/// the limit, before any buffer is allocated.
#[test]
fn log_axes_label_decades_and_minor_ticks_only_where_they_fit() {
    let wide = 10.0..200_000.0;
    let labels: Vec<String> = [10.0, 20.0, 60.0, 100.0, 1000.0, 5000.0, 100_000.0, 1e6]
        .iter()
        .map(|&v| log_label(v, &wide))
        .collect();
    assert_eq!(labels, ["10", "", "", "100", "1000", "", "100000", "1e6"]);
    let narrow = 10.0..300.0;
    let labels: Vec<String> = [20.0, 50.0, 60.0, 0.02].iter().map(|&v| log_label(v, &narrow)).collect();
    assert_eq!(labels, ["20", "50", "", "0.02"]);
}

#[test]
fn the_spread_comes_from_rows_of_several_frames() {
    let csv = "pipeline,lights,frames,frame_ms_median,frame_ms_min,frame_ms_max\n\
               naive,16,5,10,9,12\nnaive,64,1,20,20,20\nforward-plus,16,5,8,7,9\n";
    let t = Table::parse(csv).expect("table");
    let s = spread_over_lights(&t, "frame_ms_median", "frame_ms_min", "frame_ms_max");
    assert_eq!(s.len(), 2);
    assert_eq!(s[0].1, vec![SpreadPoint { x: 16.0, lo: 9.0, mid: 10.0, hi: 12.0 }]);
}

#[test]
fn figures_too_tall_for_their_rows_are_refused() {
    let mut csv = BENCH.lines().next().expect("header").to_string();
    for i in 0..200_000 {
        csv.push_str(&format!(
            "\n\"llvmpipe\",default,clustered-forward-{i},,64,96,64,20.0,,0.03,false,1.2,0.07,0.60"
        ));
    }
    let dir = std::env::temp_dir().join(format!("manylight_plot_rows_{}", std::process::id()));
    let error = figures(&csv, &dir).expect_err("too many rows for one figure");
    let _ = std::fs::remove_dir_all(&dir);
    assert!(format!("{error:#}").contains("MAX_FIGURE_HEIGHT"), "{error:#}");
    assert!(figure_height(200, 44, usize::MAX, 450).is_err());
    assert!(figure_height(200, 26, (u32::MAX / 26) as usize + 1, 800).is_err());
    assert_eq!(figure_height(200, 44, 1, 450).expect("fits"), 450);
}

#[test]
fn pareto_front_keeps_points_no_other_beats() {
    let p = |label: &str, frame_ms, flip_mean| AccuracyPoint { label: label.into(), frame_ms, flip_mean };
    let points = [
        p("reference", 8000.0, 0.0),
        p("fast exact", 170.0, 0.0001),
        p("faster", 160.0, 0.004),
        p("worse", 200.0, 0.01),
        p("oracle, forward (exact per-pixel lists)", 150.0, 0.0),
    ];
    // The reference is exact: nothing beats its error, so it ends the front; the oracle
    // beats everything but is not a configuration, so it is not on the front.
    assert_eq!(pareto_front(&points), vec![2, 1, 0]);
}

#[test]
fn figures_are_written_as_png() {
    let dir = std::env::temp_dir().join(format!("manylight-plot-test-{}", std::process::id()));
    let files = figures(BENCH, &dir).expect("figures");
    let names: Vec<String> =
        files.iter().map(|f| f.file_name().and_then(|n| n.to_str()).unwrap_or("").to_string()).collect();
    assert_eq!(
        names,
        ["bench_frame_time.png", "bench_culling_ratio.png", "bench_passes.png", "bench_memory.png"]
    );
    for f in &files {
        let img = image::open(f).expect("a PNG").to_rgb8();
        // Something besides the white background was drawn.
        assert!(img.pixels().filter(|p| p.0 != [255, 255, 255]).count() > 1000, "{}", f.display());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_csv_of_another_kind_is_refused() {
    let err = figures("a,b\n1,2\n", Path::new("/nonexistent")).expect_err("refused");
    assert!(err.to_string().contains("not a CSV"), "{err}");
}
