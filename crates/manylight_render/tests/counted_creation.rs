//! The frame counters (`FrameReport::buffers_created`, `bind_groups_created`,
//! `blocking_waits`, `cpu.upload_bytes`) are complete only if every buffer, bind group, upload
//! and GPU wait of the renderer goes through `GpuContext`. This test reads the render and app crates' sources and
//! fails on any direct call to the device. It needs no GPU.

use std::path::{Path, PathBuf};

/// Calls that bypass the counters, and what to call instead.
const DIRECT: [(&str, &str); 6] = [
    ("device.create_buffer(", "GpuContext::create_buffer"),
    ("queue.write_buffer(", "GpuContext::write_buffer"),
    ("queue.write_texture(", "GpuContext::write_texture"),
    ("device.create_buffer_init(", "GpuContext::create_buffer_init"),
    ("device.create_bind_group(", "GpuContext::create_bind_group"),
    ("PollType::Wait", "GpuContext::wait_for"),
];

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        panic!("cannot read {}", dir.display());
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn every_buffer_bind_group_upload_and_wait_is_counted() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    sources(&crates.join("manylight_render/src"), &mut files);
    sources(&crates.join("manylight_app/src"), &mut files);
    assert!(files.len() > 20, "found only {} source files", files.len());
    let mut found = Vec::new();
    for file in &files {
        // The context itself makes the counted calls.
        if file.ends_with("src/context.rs") {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        for (line_number, line) in text.lines().enumerate() {
            for (call, instead) in DIRECT {
                if line.contains(call) && !line.trim_start().starts_with("//") {
                    found.push(format!("{}:{}: `{call}`, use {instead}", file.display(), line_number + 1));
                }
            }
        }
    }
    assert!(found.is_empty(), "uncounted GPU calls:\n{}", found.join("\n"));
}
