//! Structure-aware fuzzing of the glTF loader.
//!
//! Each case starts from a real scene (`assets/BoxTextured`, `assets/CornellBox`,
//! `assets/TextureCoordinateTest`, the fixtures in `tests/data`, and, rarely, `DamagedHelmet`
//! rebuilt around its JSON chunk, its geometry and a small PNG), parses its JSON as a
//! `serde_json::Value` and applies a few mutations that know the glTF structure: counts,
//! offsets, strides, lengths, indices, component types and URIs set to edge values, node
//! children made into cycles, deep chains and deep, wide trees, accessors declaring billions
//! of elements, arrays repeated to multiply instances (up to and past the instance budget) and
//! images, values of the wrong JSON type, deeply nested arrays, and normal-mapped meshes with
//! hostile topologies for tangent generation (fans, repeated triangles, zero-area triangles,
//! duplicated and degenerate uvs, one position with many uvs, random triangle soups). A GLB is re-packed and then, sometimes, its header and chunk headers are
//! flipped, overwritten or truncated.
//!
//! Every case is written to a temporary folder (next to the seed's buffers and images) and
//! loaded with `load_gltf` under tight `LoadOptions` budgets, on a worker thread with a time
//! limit, under a counting global allocator. It must return a scene or a typed error naming
//! the file: never a panic (`SceneError::Internal`), never a hang, never a peak heap growth
//! over [`PEAK_LIMIT`], and a returned scene must validate and stay within every budget.
//!
//! `MANYLIGHT_FUZZ_CASES` sets the number of cases (default 10 000), `MANYLIGHT_FUZZ_SEED`
//! the random seed (default fixed, so CI runs are reproducible). A failing case is shrunk
//! and written to `MANYLIGHT_FUZZ_OUT` (default the system temporary folder).

#[path = "support/counting_alloc.rs"]
mod counting_alloc;

use manylight_scene::{LoadOptions, Scene, SceneError, load_gltf};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

#[global_allocator]
static ALLOC: counting_alloc::Counting = counting_alloc::Counting;

/// Cases run when `MANYLIGHT_FUZZ_CASES` is not set.
const DEFAULT_CASES: u32 = 10_000;

/// Longest one case may take.
const CASE_TIMEOUT: Duration = Duration::from_secs(20);

/// Largest peak heap growth of one load under [`budgets`].
const PEAK_LIMIT: usize = 64 << 20;

/// The tight budgets every case loads under.
fn budgets() -> LoadOptions {
    LoadOptions {
        max_texture_size: 1024,
        // Refused rather than decoded at full size to be scaled down: the decode would not be
        // bounded by the 1024-pixel limit.
        oversized_textures: manylight_scene::OversizedTextures::Refuse,
        max_json_bytes: 1 << 20,
        max_json_values: 100_000,
        max_glb_bytes: 4 << 20,
        max_buffer_bytes: 2 << 20,
        max_accessor_bytes: 1 << 20,
        max_vertices: 100_000,
        max_indices: 300_000,
        max_instances: 10_000,
        max_lights: 1_000,
        max_node_depth: 64,
        max_image_bytes: 4 << 20,
        max_tangent_triangles: 100_000,
    }
}

// ---------------------------------------------------------------------------------------------
// Seeds

/// A scene to mutate: its JSON, its GLB binary chunk (for a GLB) and the files next to it.
struct Seed {
    name: &'static str,
    json: Value,
    glb_bin: Option<Vec<u8>>,
    /// The folder cases of this seed are written to (with the seed's files copied there).
    dir: PathBuf,
}

fn manifest() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn assets() -> PathBuf {
    manifest().join("../../assets")
}

/// Splits a GLB into its JSON (parsed) and binary chunk.
fn split_glb(bytes: &[u8]) -> (Value, Vec<u8>) {
    let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as usize;
    let json_len = u32_at(12);
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).expect("seed JSON");
    let bin_at = 20 + json_len;
    let bin = if bin_at + 8 <= bytes.len() {
        bytes[bin_at + 8..bin_at + 8 + u32_at(bin_at)].to_vec()
    } else {
        vec![]
    };
    (json, bin)
}

/// Packs a GLB from JSON text and an optional binary chunk (both padded to 4 bytes).
fn pack_glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = Vec::with_capacity(28 + json.len() + bin.map_or(0, <[u8]>::len));
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes()); // total length, set below
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    if let Some(bin) = bin {
        let mut bin = bin.to_vec();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    let total = out.len() as u32;
    out[8..12].copy_from_slice(&total.to_le_bytes());
    out
}

/// Copies every file of `from` into `to`.
fn copy_folder(from: &Path, to: &Path) {
    for entry in std::fs::read_dir(from).expect("seed folder") {
        let path = entry.expect("entry").path();
        if path.is_file() {
            std::fs::copy(&path, to.join(path.file_name().expect("name"))).expect("copy seed file");
        }
    }
}

/// DamagedHelmet with its JSON chunk and geometry as they are, and its five JPEG textures
/// (1.3 MB, 2048 x 2048) replaced by one small PNG, so a case costs milliseconds.
fn damaged_helmet() -> (Value, Vec<u8>) {
    let glb = std::fs::read(assets().join("DamagedHelmet/DamagedHelmet.glb")).expect("DamagedHelmet");
    let (mut json, bin) = split_glb(&glb);
    let geometry_end = 558_504; // the end of buffer view 3 (texture coordinates)
    let mut bin = bin[..geometry_end].to_vec();
    let png = std::fs::read(assets().join("BoxTextured/CesiumLogoFlat.png")).expect("png");
    let png_at = bin.len();
    bin.extend_from_slice(&png);
    for view in 4..9 {
        json["bufferViews"][view] = json!({ "buffer": 0, "byteOffset": png_at, "byteLength": png.len() });
        json["images"][view - 4] = json!({ "bufferView": view, "mimeType": "image/png" });
    }
    json["buffers"][0]["byteLength"] = json!(bin.len());
    (json, bin)
}

fn seeds(root: &Path) -> Vec<Seed> {
    let mut out = Vec::new();
    let mut add = |name: &'static str, json: Value, glb_bin: Option<Vec<u8>>, files: Option<PathBuf>| {
        let dir = root.join(name);
        std::fs::create_dir_all(&dir).expect("seed dir");
        if let Some(files) = files {
            copy_folder(&files, &dir);
        }
        out.push(Seed { name, json, glb_bin, dir });
    };
    let read_json = |path: PathBuf| -> Value {
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
        serde_json::from_slice(bytes).expect("seed JSON")
    };
    for (name, folder, file) in [
        ("BoxTextured", "BoxTextured", "BoxTextured.gltf"),
        ("CornellBox", "CornellBox", "CornellBox.gltf"),
        ("TextureCoordinateTest", "TextureCoordinateTest", "TextureCoordinateTest.gltf"),
    ] {
        let folder = assets().join(folder);
        add(name, read_json(folder.join(file)), None, Some(folder));
    }
    let data = manifest().join("tests/data");
    add("features", read_json(data.join("features.gltf")), None, None);
    add("png16", read_json(data.join("png16.gltf")), None, Some(data.clone()));
    let (json, bin) = split_glb(&std::fs::read(data.join("triangle.glb")).expect("triangle.glb"));
    add("triangle_glb", json, Some(bin), None);
    // Files the specification allows that strict parsers refuse: quantized attributes, and a
    // GLB whose other buffers are a file and a `data:` URI.
    add("quantized", read_json(data.join("quantized.gltf")), None, None);
    let (json, bin) =
        split_glb(&std::fs::read(data.join("several_buffers.glb")).expect("several_buffers.glb"));
    add("several_buffers_glb", json, Some(bin), Some(data.clone()));
    let (json, bin) = damaged_helmet();
    add("DamagedHelmet", json, Some(bin), None);
    out
}

/// Seed index for a seed pick: DamagedHelmet (the last, and the slowest) gets 1 slot of 32.
fn pick_seed(pick: u8, seeds: usize) -> usize {
    match pick % 32 {
        0 => seeds - 1,
        p => p as usize % (seeds - 1),
    }
}

// ---------------------------------------------------------------------------------------------
// Mutations

/// SplitMix64: sub-choices of one mutation come from its 64-bit value, so shrinking that
/// value towards zero simplifies the mutation.
struct Mix(u64);

impl Mix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        if n == 0 { 0 } else { (self.next() % n as u64) as usize }
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

#[derive(Clone, Debug)]
enum Seg {
    Key(String),
    Index(usize),
}

/// Paths to every value of `v` (the root included), breadth first.
fn paths(v: &Value) -> Vec<Vec<Seg>> {
    let mut out = vec![vec![]];
    let mut at = 0;
    while at < out.len() {
        let path = out[at].clone();
        match get(v, &path) {
            Some(Value::Object(m)) => {
                out.extend(m.keys().map(|k| [path.clone(), vec![Seg::Key(k.clone())]].concat()))
            }
            Some(Value::Array(a)) => {
                out.extend((0..a.len()).map(|i| [path.clone(), vec![Seg::Index(i)]].concat()))
            }
            _ => {}
        }
        at += 1;
    }
    out
}

fn get<'a>(v: &'a Value, path: &[Seg]) -> Option<&'a Value> {
    path.iter().try_fold(v, |v, s| match s {
        Seg::Key(k) => v.get(k),
        Seg::Index(i) => v.get(*i),
    })
}

fn get_mut<'a>(v: &'a mut Value, path: &[Seg]) -> Option<&'a mut Value> {
    path.iter().try_fold(v, |v, s| match s {
        Seg::Key(k) => v.get_mut(k),
        Seg::Index(i) => v.get_mut(*i),
    })
}

/// Numbers at the edges of the types the loader reads (u8, u16, u32, usize): mostly
/// non-negative integers, which the JSON schema accepts, now and then negative or fractional.
fn edge_number(m: &mut Mix) -> Value {
    let unsigned = [
        0u64,
        1,
        2,
        3,
        4,
        7,
        12,
        255,
        256,
        65_535,
        65_536,
        i32::MAX as u64,
        1 << 31,
        u32::MAX as u64,
        1 << 32,
        4_000_000_000,
        1 << 53,
        1_000_000_000_000,
        u64::MAX,
    ];
    if m.below(5) > 0 {
        return json!(*m.pick(&unsigned));
    }
    let other = [
        json!(-1),
        json!(i64::MIN),
        json!(0.5),
        json!(-0.0),
        json!(1e-45),
        json!(1e35),
        json!(3.4e38),
        json!(1e39),
        json!(-1e39),
        json!(1e308),
    ];
    m.pick(&other).clone()
}

/// An index into an array of `len` elements, or just past it, or far past it.
fn edge_index(m: &mut Mix, len: usize) -> Value {
    match m.below(6) {
        0 => json!(0),
        1 => json!(len.saturating_sub(1)),
        2 => json!(len),
        3 => json!(len + 1),
        4 => json!(u32::MAX),
        _ => json!(m.below(len + 2)),
    }
}

/// URIs: hostile, malformed, other files of the folder, and the seed's own buffers inlined.
fn edge_uri(m: &mut Mix, doc: &Value, dir: &Path) -> Value {
    let files: Vec<String> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok()?.file_name().into_string().ok()).collect())
        .unwrap_or_default();
    let fixed = [
        "",
        ".",
        "./",
        "data:",
        "data:,",
        "data:application/octet-stream;base64,",
        "data:application/octet-stream;base64,AAAA",
        "data:application/octet-stream;base64,====",
        "data:image/png;base64,iVBORw0KGgo=",
        "data:image/gif;base64,R0lGODlhAQABAAAAACw=",
        "data:text/plain,hello",
        "DATA:application/octet-stream;base64,AAAA",
        "../secret.bin",
        "sub/../../secret.bin",
        "%2e%2e/secret.bin",
        "%2E%2E%2Fsecret.bin",
        "%zz",
        "%",
        "/etc/passwd",
        "/dev/zero",
        "file:///etc/passwd",
        "http://127.0.0.1/x.bin",
        "https://example.com/x.png",
        "//host/share/x",
        "C:/x.bin",
        "c:x",
        "\\\\host\\share\\x",
        "a\\..\\x",
        "does_not_exist.bin",
        "nul\u{0}.bin",
        "\u{00e9}t\u{00e9}.bin",
        "case.gltf",
        "case.glb",
    ];
    match m.below(4) {
        0 if !files.is_empty() => json!(m.pick(&files)),
        1 if !files.is_empty() => {
            // A sibling file inlined as a `data:` URI.
            use base64::Engine as _;
            let bytes = std::fs::read(dir.join(m.pick(&files))).unwrap_or_default();
            let bytes = &bytes[..bytes.len().min(64 << 10)];
            json!(format!(
                "data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(bytes)
            ))
        }
        2 => {
            let uris: Vec<&Value> = ["buffers", "images"]
                .iter()
                .filter_map(|k| doc.get(k)?.as_array())
                .flatten()
                .filter_map(|e| e.get("uri"))
                .collect();
            if uris.is_empty() { json!("x.bin") } else { (*m.pick(&uris)).clone() }
        }
        _ => json!(m.pick(&fixed)),
    }
}

/// Length of `doc[key]` as an array (0 if absent).
fn len_of(doc: &Value, key: &str) -> usize {
    doc.get(key).and_then(Value::as_array).map_or(0, Vec::len)
}

/// A value for field `field` of an object of array `array`: an edge value of the right
/// kind, now and then one of a random kind.
fn field_value(m: &mut Mix, doc: &Value, dir: &Path, array: &str, field: &str) -> Value {
    let index_into = |m: &mut Mix, key: &str| edge_index(m, len_of(doc, key));
    match (array, field) {
        (_, "bufferView") => index_into(m, "bufferViews"),
        (_, "buffer") => index_into(m, "buffers"),
        (_, "source") => index_into(m, "images"),
        (_, "mesh") => index_into(m, "meshes"),
        (_, "camera") => index_into(m, "cameras"),
        (_, "material") => index_into(m, "materials"),
        (_, "indices" | "POSITION" | "NORMAL" | "TEXCOORD_0") => index_into(m, "accessors"),
        (_, "children" | "nodes") => {
            let n = len_of(doc, "nodes");
            json!((0..1 + m.below(3)).map(|_| edge_index(m, n)).collect::<Vec<_>>())
        }
        (_, "componentType") => json!(m.pick(&[5120, 5121, 5122, 5123, 5125, 5126, 5124, 0, 1, 9999])),
        (_, "type") if array == "accessors" => {
            json!(m.pick(&["SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4", "vec3", ""]))
        }
        (_, "type") => {
            json!(m.pick(&["point", "spot", "directional", "perspective", "orthographic", "area"]))
        }
        (_, "mode") => json!(m.below(9)),
        (_, "uri") => edge_uri(m, doc, dir),
        (_, "mimeType") => {
            json!(m.pick(&["image/png", "image/jpeg", "image/jpg", "IMAGE/PNG", "image/gif", ""]))
        }
        (_, "normalized") => json!(m.below(2) == 0),
        (_, "sparse") => json!({
            "count": edge_number(m),
            "indices": { "bufferView": index_into(m, "bufferViews"), "byteOffset": edge_number(m),
                         "componentType": m.pick(&[5121, 5123, 5125, 5126]) },
            "values": { "bufferView": index_into(m, "bufferViews"), "byteOffset": edge_number(m) }
        }),
        (_, "matrix") => json!(
            (0..16)
                .map(|i| if m.below(4) == 0 { edge_number(m) } else { json!(f32::from(i % 5 == 0)) })
                .collect::<Vec<_>>()
        ),
        (_, "translation" | "scale" | "color") => json!([edge_number(m), edge_number(m), edge_number(m)]),
        (_, "rotation" | "baseColorFactor") => json!([edge_number(m), 0, 0, edge_number(m)]),
        (_, "extensions") if array == "nodes" => {
            json!({ "KHR_lights_punctual": { "light": edge_index(m, 2) } })
        }
        _ => match m.below(8) {
            0 => json!(null),
            1 => json!("x"),
            2 => json!([]),
            3 => json!({}),
            4 => json!(true),
            _ => edge_number(m),
        },
    }
}

/// Fields worth setting, per top-level array.
fn fields_of(array: &str) -> &'static [&'static str] {
    match array {
        "accessors" => {
            &["bufferView", "byteOffset", "componentType", "normalized", "count", "type", "sparse"]
        }
        "bufferViews" => &["buffer", "byteOffset", "byteLength", "byteStride"],
        "buffers" => &["byteLength", "uri"],
        "images" => &["uri", "bufferView", "mimeType"],
        "textures" => &["source", "sampler"],
        "nodes" => {
            &["mesh", "children", "matrix", "translation", "rotation", "scale", "camera", "extensions"]
        }
        "cameras" => &["type", "perspective"],
        "materials" => &["pbrMetallicRoughness", "name"],
        "scenes" => &["nodes"],
        _ => &["name"],
    }
}

/// Applies mutation `op` with sub-choices from `value` to `doc`.
fn mutate(doc: &mut Value, op: u8, selector: u32, value: u64, dir: &Path) {
    let mut m = Mix(value ^ u64::from(selector) << 32);
    let all = || paths(doc);
    // The structure-aware mutations (2..=5, 8..=13, 16) get more weight than the generic ones.
    let op = match op % 20 {
        17 => 2,
        18 => 5,
        19 => 11,
        op => op,
    };
    match op {
        // A number anywhere set to an edge value.
        0 => {
            let numbers: Vec<Vec<Seg>> =
                all().into_iter().filter(|p| get(doc, p).is_some_and(Value::is_number)).collect();
            if !numbers.is_empty() {
                let path = numbers[selector as usize % numbers.len()].clone();
                let v = edge_number(&mut m);
                *get_mut(doc, &path).expect("path") = v;
            }
        }
        // A number anywhere nudged.
        1 => {
            let numbers: Vec<Vec<Seg>> =
                all().into_iter().filter(|p| get(doc, p).is_some_and(Value::is_number)).collect();
            if !numbers.is_empty() {
                let path = numbers[selector as usize % numbers.len()].clone();
                let slot = get_mut(doc, &path).expect("path");
                let n = slot.as_f64().unwrap_or(0.0);
                *slot = match m.below(5) {
                    0 => json!(slot.as_u64().map_or(n + 1.0, |u| u.saturating_add(1) as f64)),
                    1 => json!(slot.as_u64().map_or(n - 1.0, |u| u as f64 - 1.0)),
                    2 => json!(n * 2.0),
                    3 => json!((n / 2.0).floor()),
                    _ => json!(-n),
                };
                if let Some(f) = slot.as_f64()
                    && f.fract() == 0.0
                    && (0.0..9e15).contains(&f)
                {
                    *slot = json!(f as u64);
                }
            }
        }
        // A glTF field of an element of a top-level array set to an edge value.
        2..=4 => {
            let arrays = [
                "accessors",
                "bufferViews",
                "buffers",
                "images",
                "textures",
                "nodes",
                "cameras",
                "materials",
                "scenes",
            ];
            let array = *m.pick(&arrays);
            let n = len_of(doc, array);
            if n > 0 {
                let i = selector as usize % n;
                let field = *m.pick(fields_of(array));
                let v = field_value(&mut m, doc, dir, array, field);
                if let Some(obj) = doc[array][i].as_object_mut() {
                    obj.insert(field.to_owned(), v);
                }
            }
        }
        // A primitive's attribute, indices, mode or material.
        5 => {
            let n = len_of(doc, "meshes");
            if n > 0 {
                let mesh = selector as usize % n;
                let pointer = format!("/meshes/{mesh}/primitives");
                let prims = doc.pointer(&pointer).and_then(Value::as_array).map_or(0, Vec::len);
                if prims > 0 {
                    let p = m.below(prims);
                    let field = *m.pick(&["POSITION", "NORMAL", "TEXCOORD_0", "indices", "mode", "material"]);
                    let v = field_value(&mut m, doc, dir, "primitives", field);
                    let Some(prim) = doc.pointer_mut(&format!("{pointer}/{p}")) else { return };
                    if matches!(field, "POSITION" | "NORMAL" | "TEXCOORD_0") {
                        if let Some(attributes) = prim.get_mut("attributes").and_then(Value::as_object_mut) {
                            attributes.insert(field.to_owned(), v);
                        }
                    } else if let Some(prim) = prim.as_object_mut() {
                        prim.insert(field.to_owned(), v);
                    }
                }
            }
        }
        // A key removed anywhere.
        6 => {
            let objects: Vec<Vec<Seg>> =
                all().into_iter().filter(|p| get(doc, p).is_some_and(Value::is_object)).collect();
            let path = objects[selector as usize % objects.len()].clone();
            if let Some(obj) = get_mut(doc, &path).and_then(Value::as_object_mut)
                && !obj.is_empty()
            {
                let key = obj.keys().nth(m.below(obj.len())).expect("key").clone();
                obj.remove(&key);
            }
        }
        // An array anywhere: element removed, duplicated, swapped, cleared, or repeated many
        // times (bounded so the text stays near the JSON budget).
        7 => {
            let arrays: Vec<Vec<Seg>> =
                all().into_iter().filter(|p| get(doc, p).is_some_and(Value::is_array)).collect();
            if arrays.is_empty() {
                return;
            }
            let path = arrays[selector as usize % arrays.len()].clone();
            let arr = get_mut(doc, &path).and_then(Value::as_array_mut).expect("array");
            if arr.is_empty() {
                return;
            }
            let i = m.below(arr.len());
            match m.below(5) {
                0 => {
                    arr.remove(i);
                }
                1 => {
                    let e = arr[i].clone();
                    arr.insert(i, e);
                }
                2 => {
                    let j = m.below(arr.len());
                    arr.swap(i, j);
                }
                3 => arr.clear(),
                _ => {
                    let e = arr[i].clone();
                    let size = serde_json::to_vec(&e).map_or(1, |v| v.len()).max(1);
                    let copies = (*m.pick(&[10usize, 100, 1000, 5000])).min((768 << 10) / size);
                    arr.extend(std::iter::repeat_n(e, copies));
                }
            }
        }
        // Node children made into a cycle, a self loop or a shared child.
        8 => {
            let n = len_of(doc, "nodes");
            if n > 0 {
                let from = selector as usize % n;
                let to = match m.below(3) {
                    0 => from,
                    1 => 0,
                    _ => m.below(n),
                };
                let node = &mut doc["nodes"][from];
                if node.is_object() {
                    match node.get_mut("children").and_then(Value::as_array_mut) {
                        Some(c) => c.push(json!(to)),
                        None => node["children"] = json!([to]),
                    }
                }
            }
        }
        // A deep chain, or a deep and wide tree (every node with `branching` children, up to
        // 5 000 nodes), of new nodes hung under a node or added as a scene root.
        9 => {
            let depth = *m.pick(&[10usize, 63, 64, 65, 100, 1000, 5000]);
            let branching = if m.below(3) == 0 { *m.pick(&[2usize, 3, 10, 100]) } else { 1 };
            let Some(nodes) = doc.get_mut("nodes").and_then(Value::as_array_mut) else { return };
            let start = nodes.len();
            let mesh = if m.below(2) == 0 { Some(0) } else { None };
            // Breadth first: node k's children are branching * k + 1 ..= branching * (k + 1),
            // stopping at `depth` levels or 5 000 nodes.
            let mut count = 1usize;
            let mut level = 1usize;
            let mut width = 1usize;
            while level < depth && count + width * branching <= 5000 {
                width *= branching;
                count += width;
                level += 1;
            }
            for k in 0..count {
                let children: Vec<usize> = (branching * k + 1..=branching * (k + 1))
                    .filter(|&c| c < count)
                    .map(|c| start + c)
                    .collect();
                let mut node = if children.is_empty() { json!({}) } else { json!({ "children": children }) };
                if let Some(mesh) = mesh {
                    node["mesh"] = json!(mesh);
                }
                nodes.push(node);
            }
            let parent = if start > 0 { Some(selector as usize % start) } else { None };
            match parent {
                Some(p) if doc["nodes"][p].is_object() => {
                    match doc["nodes"][p].get_mut("children").and_then(Value::as_array_mut) {
                        Some(c) => c.push(json!(start)),
                        None => doc["nodes"][p]["children"] = json!([start]),
                    }
                }
                _ => {
                    if let Some(roots) = doc.pointer_mut("/scenes/0/nodes").and_then(Value::as_array_mut) {
                        roots.push(json!(start));
                    }
                }
            }
        }
        // An accessor declaring billions of elements, with or without its buffer view.
        10 => {
            let n = len_of(doc, "accessors");
            if n > 0 {
                let a = &mut doc["accessors"][selector as usize % n];
                if a.is_object() {
                    a["count"] =
                        json!(m.pick(&[2_147_483_648u64, 4_294_967_295, 4_000_000_000, 1 << 40, u64::MAX]));
                    if m.below(2) == 0
                        && let Some(o) = a.as_object_mut()
                    {
                        o.remove("bufferView");
                    }
                }
            }
        }
        // A buffer view's stride or offset, or an accessor's offset, set to an edge value.
        11 => {
            let (array, fields): (&str, &[&str]) = if m.below(2) == 0 {
                ("bufferViews", &["byteStride", "byteOffset", "byteLength"])
            } else {
                ("accessors", &["byteOffset", "count"])
            };
            let n = len_of(doc, array);
            if n > 0 {
                let field = *m.pick(fields);
                let v = match m.below(3) {
                    0 => json!(m.pick(&[0u64, 1, 2, 3, 4, 5, 6, 8, 12, 248, 252, 256, 1 << 31])),
                    _ => edge_number(&mut m),
                };
                if let Some(o) = doc[array][selector as usize % n].as_object_mut() {
                    o.insert(field.to_owned(), v);
                }
            }
        }
        // Instances multiplied: many nodes drawing one mesh whose first primitive is repeated
        // (nodes x primitives instances from a few kilobytes).
        12 => {
            let meshes = len_of(doc, "meshes");
            if meshes == 0 {
                return;
            }
            let mesh = selector as usize % meshes;
            // Up to and past the 10 000 instances `budgets` allows (100 x 100, 1000 x 10,
            // 5000 x 2 are exactly that, before the seed's own).
            let nodes_count = *m.pick(&[1usize, 10, 100, 1000, 5000]);
            let prims_count = *m.pick(&[1usize, 2, 10, 100, 1000]);
            if let Some(prims) =
                doc.pointer_mut(&format!("/meshes/{mesh}/primitives")).and_then(Value::as_array_mut)
                && let Some(p) = prims.first().cloned()
            {
                prims.extend(std::iter::repeat_n(p, prims_count - 1));
            }
            let Some(nodes) = doc.get_mut("nodes").and_then(Value::as_array_mut) else { return };
            let start = nodes.len();
            nodes.extend(std::iter::repeat_n(json!({ "mesh": mesh }), nodes_count));
            if let Some(roots) = doc.pointer_mut("/scenes/0/nodes").and_then(Value::as_array_mut) {
                roots.extend((start..start + nodes_count).map(|i| json!(i)));
            }
        }
        // Images multiplied: many images, textures and materials naming one source.
        13 => {
            let images = len_of(doc, "images");
            if images == 0 {
                return;
            }
            let image = doc["images"][selector as usize % images].clone();
            let count = *m.pick(&[10usize, 100, 1000]);
            let first = len_of(doc, "images");
            let textures = len_of(doc, "textures");
            let materials = len_of(doc, "materials");
            for k in 0..count {
                doc["images"].as_array_mut().expect("images").push(image.clone());
                if let Some(t) = doc.get_mut("textures").and_then(Value::as_array_mut) {
                    t.push(json!({ "source": first + k }));
                }
                if let Some(mat) = doc.get_mut("materials").and_then(Value::as_array_mut) {
                    mat.push(
                        json!({ "pbrMetallicRoughness": { "baseColorTexture": { "index": textures + k } } }),
                    );
                }
            }
            // Every new material drawn by a copy of primitive 0 of mesh 0.
            if let Some(prims) = doc.pointer_mut("/meshes/0/primitives").and_then(Value::as_array_mut)
                && let Some(p) = prims.first().cloned()
            {
                for k in 0..count {
                    let mut p = p.clone();
                    if let Some(o) = p.as_object_mut() {
                        o.insert("material".to_owned(), json!(materials + k));
                    }
                    prims.push(p);
                }
            }
        }
        // A hostile topology on a new normal-mapped primitive, so tangents are generated.
        16 => add_topology(doc, &mut m),
        // A value anywhere replaced by a value of another kind, or by another value of the doc.
        14 => {
            let every = all();
            let path = every[selector as usize % every.len()].clone();
            let v = if m.below(2) == 0 {
                let other = &every[m.below(every.len())];
                get(doc, other).cloned().unwrap_or(Value::Null)
            } else {
                match m.below(7) {
                    0 => json!(null),
                    1 => json!(""),
                    2 => json!([]),
                    3 => json!({}),
                    4 => json!(false),
                    5 => json!("@@DEEP@@"),
                    _ => edge_number(&mut m),
                }
            };
            if !path.is_empty()
                && let Some(slot) = get_mut(doc, &path)
            {
                *slot = v;
            }
        }
        // Deeply nested arrays somewhere (substituted in the text after serialising).
        _ => {
            let objects: Vec<Vec<Seg>> =
                all().into_iter().filter(|p| get(doc, p).is_some_and(Value::is_object)).collect();
            let path = objects[selector as usize % objects.len()].clone();
            let key = *m.pick(&["extras", "extensions", "name", "children", "attributes"]);
            if let Some(o) = get_mut(doc, &path).and_then(Value::as_object_mut) {
                o.insert(key.to_owned(), json!("@@DEEP@@"));
            }
        }
    }
}

/// Appends `value` to the top-level array `key` (created when absent) and returns its index;
/// `None` when `key` holds something else.
fn push(doc: &mut Value, key: &str, value: Value) -> Option<usize> {
    let obj = doc.as_object_mut()?;
    let arr = obj.entry(key).or_insert_with(|| json!([])).as_array_mut()?;
    arr.push(value);
    Some(arr.len() - 1)
}

/// A 2 x 2 flat normal map as a `data:` URI.
fn normal_map_uri() -> String {
    use base64::Engine as _;
    let img = image::RgbaImage::from_pixel(2, 2, image::Rgba([128, 128, 255, 255]));
    let mut png = std::io::Cursor::new(Vec::new());
    img.write_to(&mut png, image::ImageFormat::Png).expect("encode PNG");
    format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(png.into_inner()))
}

/// Adds a mesh with a hostile topology for tangent generation (MikkTSpace's costs grow with
/// the triangles around a vertex, on an edge and at a position): a fan around one vertex,
/// one triangle repeated, zero-area triangles, duplicated or degenerate uvs, one position
/// with a different uv per triangle, or a random soup of triangles over a few vertices. Its
/// primitive has `TEXCOORD_0`, no `TANGENT` and a normal-mapped material; a new root node
/// draws it. The geometry goes in a new `data:` buffer (within the JSON budget).
fn add_topology(doc: &mut Value, m: &mut Mix) {
    // Triangles: mostly small (each case stays fast), now and then ten thousand.
    let n = *m.pick(&[1usize, 3, 30, 300, 300, 1000, 1000, 3000, 10_000]);
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut uvs: Vec<[f32; 2]> = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    let ring = |k: usize| {
        let a = std::f32::consts::TAU * k as f32 / n as f32;
        [a.cos(), a.sin(), 0.0]
    };
    match m.below(6) {
        // A fan around vertex 0.
        0 => {
            positions.push([0.0; 3]);
            positions.extend((0..=n).map(ring));
            uvs.extend(positions.iter().map(|p| [p[0] * 0.5 + 0.5, 0.5 - p[1] * 0.5]));
            indices.extend((0..n as u32).flat_map(|k| [0, k + 1, k + 2]));
        }
        // One triangle repeated (with either winding now and then).
        1 => {
            positions.extend([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
            uvs.extend([[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]]);
            let flip = m.below(2) == 0;
            indices.extend((0..n).flat_map(|k| if flip && k % 3 == 0 { [0, 2, 1] } else { [0, 1, 2] }));
        }
        // Zero-area triangles (two corners at one position), some next to good ones.
        2 => {
            for k in 0..n {
                let p = ring(k);
                let base = positions.len() as u32;
                positions.extend([p, p, [p[0], p[1], 1.0]]);
                uvs.extend([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
                indices.extend(if k % 4 == 0 { [base, base + 2, 0] } else { [base, base + 1, base + 2] });
            }
        }
        // A strip whose uvs are all equal, or all on one line (zero uv area everywhere).
        3 => {
            let equal = m.below(2) == 0;
            for k in 0..n + 2 {
                positions.push([(k / 2) as f32, (k % 2) as f32, 0.0]);
                uvs.push(if equal { [0.5, 0.5] } else { [k as f32 / (n + 2) as f32, 0.25] });
            }
            indices.extend((0..n as u32).flat_map(|k| [k, k + 1, k + 2]));
        }
        // A fan whose centre is repeated for each triangle with its own uv.
        4 => {
            for k in 0..n {
                let base = positions.len() as u32;
                positions.extend([[0.0; 3], ring(k), ring(k + 1)]);
                uvs.extend([[k as f32 / n as f32, 0.0], [1.0, 0.0], [1.0, 1.0]]);
                indices.extend([base, base + 1, base + 2]);
            }
        }
        // A soup of random triangles over a few vertices: edges shared by many triangles
        // with both windings.
        _ => {
            let v = 3 + m.below(14);
            for k in 0..v {
                positions.push([(k % 3) as f32, (k / 3 % 3) as f32, (k / 9) as f32]);
                uvs.push([(k % 4) as f32 * 0.25, (k / 4) as f32 * 0.25]);
            }
            indices.extend((0..3 * n).map(|_| m.below(v) as u32));
        }
    }
    let max_index = indices.iter().copied().max().unwrap_or(0);
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    let uv_at = bin.len();
    bin.extend(uvs.iter().flatten().flat_map(|f| f.to_le_bytes()));
    let index_at = bin.len();
    let component = match m.below(3) {
        0 if max_index < 256 => {
            bin.extend(indices.iter().map(|&i| i as u8));
            5121
        }
        1 if max_index < 65_536 => {
            bin.extend(indices.iter().flat_map(|&i| (i as u16).to_le_bytes()));
            5123
        }
        _ => {
            bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
            5125
        }
    };
    let index_end = bin.len();
    let buffer = {
        use base64::Engine as _;
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bin)
        );
        push(doc, "buffers", json!({ "byteLength": bin.len(), "uri": uri }))
    };
    let Some(buffer) = buffer else { return };
    let views = [(0, uv_at), (uv_at, index_at), (index_at, index_end)].map(|(at, end)| {
        push(doc, "bufferViews", json!({ "buffer": buffer, "byteOffset": at, "byteLength": end - at }))
    });
    let [Some(pv), Some(uv), Some(iv)] = views else { return };
    let accessors = [
        json!({ "bufferView": pv, "componentType": 5126, "count": positions.len(), "type": "VEC3" }),
        json!({ "bufferView": uv, "componentType": 5126, "count": uvs.len(), "type": "VEC2" }),
        json!({ "bufferView": iv, "componentType": component, "count": indices.len(), "type": "SCALAR" }),
    ]
    .map(|a| push(doc, "accessors", a));
    let [Some(pa), Some(ua), Some(ia)] = accessors else { return };
    let Some(image) = push(doc, "images", json!({ "uri": normal_map_uri() })) else { return };
    let Some(texture) = push(doc, "textures", json!({ "source": image })) else { return };
    let Some(material) = push(doc, "materials", json!({ "normalTexture": { "index": texture } })) else {
        return;
    };
    let primitive =
        json!({ "attributes": { "POSITION": pa, "TEXCOORD_0": ua }, "indices": ia, "material": material });
    let Some(mesh) = push(doc, "meshes", json!({ "primitives": [primitive] })) else { return };
    let Some(node) = push(doc, "nodes", json!({ "mesh": mesh })) else { return };
    if let Some(roots) = doc.pointer_mut("/scenes/0/nodes").and_then(Value::as_array_mut) {
        roots.push(json!(node));
    }
}

/// Replaces the deep-nesting placeholders with `depth` nested arrays.
fn expand_deep(text: String, depth: usize) -> Vec<u8> {
    if !text.contains("\"@@DEEP@@\"") {
        return text.into_bytes();
    }
    text.replace("\"@@DEEP@@\"", &format!("{}{}", "[".repeat(depth), "]".repeat(depth))).into_bytes()
}

/// Byte-level damage to a GLB container (header, chunk headers, length) or to JSON text.
fn damage_bytes(bytes: &mut Vec<u8>, op: u8, selector: u32, value: u64, glb: bool) {
    let mut m = Mix(value ^ u64::from(selector) << 32);
    if bytes.is_empty() {
        return;
    }
    let len = bytes.len();
    // Offsets of the GLB header fields and of the second chunk's header.
    let json_len =
        if glb && len >= 16 { u32::from_le_bytes(bytes[12..16].try_into().expect("4")) as usize } else { 0 };
    let headers = [0usize, 4, 8, 12, 16, 20 + json_len, 24 + json_len];
    match op % 5 {
        0 if glb => {
            let at = *m.pick(&headers) + m.below(4);
            if at < len {
                bytes[at] ^= 1 << m.below(8);
            }
        }
        1 if glb => {
            let at = *m.pick(&headers);
            let v = *m.pick(&[
                0u32,
                1,
                4,
                12,
                28,
                len as u32 - 1,
                len as u32,
                len as u32 + 1,
                0x7FFF_FFFF,
                u32::MAX,
            ]);
            if at + 4 <= len {
                bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
            }
        }
        2 => {
            let cut = if m.below(2) == 0 { m.below(64.min(len)) } else { m.below(len) };
            bytes.truncate(cut);
        }
        3 if glb => {
            // An extra chunk: unknown, a second JSON or a second BIN, possibly cut off.
            let kind = *m.pick(&[b"XTRA", b"JSON", b"BIN\0"]);
            let n = *m.pick(&[0u32, 4, 8, 0xFFFF_FFF0]);
            bytes.extend_from_slice(&n.to_le_bytes());
            bytes.extend_from_slice(kind);
            bytes.extend(std::iter::repeat_n(0u8, (n as usize).min(8)));
            let total = bytes.len() as u32;
            bytes[8..12].copy_from_slice(&total.to_le_bytes());
        }
        _ => {
            let at = m.below(len);
            bytes[at] = *m.pick(&[0u8, b'"', b'{', b'[', b',', 0xFF, 0xEF, b'\\']);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Running a case

/// One generated case: a seed, JSON mutations, and byte damage.
type Plan = (u8, Vec<(u8, u32, u64)>, Vec<(u8, u32, u64)>, u8);

/// Builds the bytes of a case and the name of its file.
fn build(seed: &Seed, plan: &Plan) -> (Vec<u8>, &'static str) {
    let (_, ops, damage, deep) = plan;
    let mut doc = seed.json.clone();
    for &(op, selector, value) in ops {
        mutate(&mut doc, op, selector, value, &seed.dir);
    }
    let depth = [100usize, 127, 128, 129, 5_000, 200_000][*deep as usize % 6];
    let json = expand_deep(serde_json::to_string(&doc).expect("serialize"), depth);
    let glb = seed.glb_bin.is_some();
    let mut bytes = match &seed.glb_bin {
        Some(bin) => pack_glb(&json, Some(bin)),
        None => json,
    };
    // Damaged JSON text rarely gets past the parser: only one damage plan in four applies to
    // a `.gltf`, all of them to a GLB's container.
    for &(op, selector, value) in damage.iter().filter(|&&(op, ..)| glb || op % 4 == 0) {
        damage_bytes(&mut bytes, op / 4, selector, value, glb);
    }
    (bytes, if glb { "case.glb" } else { "case.gltf" })
}

/// What a load returned and cost.
struct Outcome {
    result: Result<Scene, SceneError>,
    peak: usize,
    elapsed: Duration,
}

fn load_timed(path: &Path, options: LoadOptions) -> Option<Outcome> {
    let owned = path.to_owned();
    let (result, peak, elapsed) = counting_alloc::measure(CASE_TIMEOUT, move || load_gltf(&owned, &options))?;
    Some(Outcome { result, peak, elapsed })
}

/// Checks everything a loaded scene must satisfy under `o`.
fn check_scene(scene: &Scene, o: &LoadOptions) -> Result<(), String> {
    scene.validate().map_err(|e| format!("loaded scene fails validation: {e}"))?;
    let vertices: usize = scene.meshes.iter().map(|m| m.vertices.len()).sum();
    let indices: usize = scene.meshes.iter().map(|m| m.indices.len()).sum();
    let mut textures: Vec<&std::sync::Arc<manylight_core::TextureData>> =
        scene.materials.iter().filter_map(|m| m.base_color_texture.as_ref().map(|t| &t.image)).collect();
    textures.sort_by_key(|t| std::sync::Arc::as_ptr(t));
    textures.dedup_by_key(|t| std::sync::Arc::as_ptr(t));
    let image_bytes: usize = textures.iter().map(|t| t.rgba8.len()).sum();
    let checks = [
        ("instances", scene.instances.len() as u64, o.max_instances),
        ("lights", scene.lights.len() as u64, o.max_lights),
        ("vertices", vertices as u64, o.max_vertices),
        ("indices", indices as u64, o.max_indices),
        ("image bytes", image_bytes as u64, o.max_image_bytes),
    ];
    for (i, c) in scene.cameras.iter().enumerate() {
        let p = c.projection;
        let far_ok = p.far.is_finite() || p.is_infinite();
        if !(p.fov_y.is_finite() && p.near.is_finite() && far_ok && p.matrix(1.5).is_finite()) {
            return Err(format!("camera {i} has an unusable projection {p:?}"));
        }
    }
    for (what, got, limit) in checks {
        if got > limit {
            return Err(format!("loaded scene has {got} {what}, over the budget of {limit}"));
        }
    }
    Ok(())
}

/// Outcome counts for the summary.
#[derive(Default)]
struct Stats {
    ok: u32,
    errors: std::collections::BTreeMap<String, u32>,
    max_peak: usize,
    max_time: Duration,
    slowest: String,
}

/// The variant name of an error (its Debug form up to the first brace).
fn variant(e: &SceneError) -> String {
    let debug = format!("{e:?}");
    debug.split([' ', '{', '(']).next().unwrap_or("").to_owned()
}

/// Where failing cases are written.
fn failure_dir() -> PathBuf {
    std::env::var_os("MANYLIGHT_FUZZ_OUT")
        .map_or_else(|| std::env::temp_dir().join("manylight_fuzz_failures"), PathBuf::from)
}

fn run_case(
    seeds: &[Seed],
    plan: &Plan,
    options: &LoadOptions,
    stats: &Mutex<Stats>,
) -> Result<(), TestCaseError> {
    let seed = &seeds[pick_seed(plan.0, seeds.len())];
    let (bytes, file) = build(seed, plan);
    let path = seed.dir.join(file);
    std::fs::write(&path, &bytes).expect("write case");
    let fail = |why: String| {
        let dir = failure_dir();
        let _ = std::fs::create_dir_all(&dir);
        let saved = dir.join(format!("{}_{file}", seed.name));
        let _ = std::fs::write(&saved, &bytes);
        TestCaseError::fail(format!(
            "{} (seed {}, saved to {}): {why}",
            path.display(),
            seed.name,
            saved.display()
        ))
    };
    let Some(out) = load_timed(&path, *options) else {
        return Err(fail(format!("no answer within {CASE_TIMEOUT:?}")));
    };
    let mut s = stats.lock().unwrap_or_else(|e| e.into_inner());
    s.max_peak = s.max_peak.max(out.peak);
    if out.elapsed > s.max_time {
        s.max_time = out.elapsed;
        s.slowest = seed.name.to_owned();
    }
    if out.peak > PEAK_LIMIT {
        return Err(fail(format!("peak heap growth {} bytes, over {PEAK_LIMIT}", out.peak)));
    }
    match out.result {
        Ok(scene) => {
            check_scene(&scene, options).map_err(fail)?;
            s.ok += 1;
        }
        Err(e) => {
            if matches!(e, SceneError::Internal { .. }) {
                return Err(fail(format!("the loader panicked: {e}")));
            }
            let message = e.to_string();
            if !message.contains(&path.display().to_string()) {
                return Err(fail(format!("the error does not name the file: {message}")));
            }
            *s.errors.entry(variant(&e)).or_default() += 1;
        }
    }
    Ok(())
}

fn env_number(name: &str) -> Option<u64> {
    let v = std::env::var(name).ok()?;
    Some(v.trim().parse().unwrap_or_else(|_| panic!("{name}={v} is not a number")))
}

#[test]
fn mutated_real_scenes_load_or_fail_with_a_typed_error_within_budgets() {
    let cases = env_number("MANYLIGHT_FUZZ_CASES").map_or(DEFAULT_CASES, |n| n as u32);
    let seed = env_number("MANYLIGHT_FUZZ_SEED").unwrap_or(0x6d61_6e79_6c69_6768);
    let root = std::env::temp_dir().join(format!("manylight_fuzz_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let seeds = seeds(&root);
    let options = budgets();
    // Every seed loads as it is, under the tight budgets.
    for s in &seeds {
        let (bytes, file) = build(s, &(0, vec![], vec![], 0));
        let path = s.dir.join(file);
        std::fs::write(&path, bytes).expect("write seed");
        let out = load_timed(&path, options).expect("seed loads in time");
        let scene = out.result.unwrap_or_else(|e| panic!("seed {} must load: {e}", s.name));
        check_scene(&scene, &options).unwrap_or_else(|e| panic!("seed {}: {e}", s.name));
    }
    // A regression aborts here rather than taking the machine's memory.
    counting_alloc::set_cap(4 << 30);

    let mut seed_bytes = [0u8; 32];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 512,
        max_shrink_time: 120_000,
        ..Config::default()
    };
    let mut runner = TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed_bytes));
    let op = (any::<u8>(), any::<u32>(), any::<u64>());
    let strategy = (
        any::<u8>(),
        prop::collection::vec(op, 1..=4),
        // Byte damage in one case of four.
        prop::collection::vec(op, 0..=3).prop_map(|d| if d.len() == 3 { d[..1].to_vec() } else { vec![] }),
        any::<u8>(),
    );
    let stats = Mutex::new(Stats::default());
    let start = Instant::now();
    let result = runner.run(&strategy, |plan| run_case(&seeds, &plan, &options, &stats));
    let elapsed = start.elapsed();
    let s = stats.into_inner().unwrap_or_else(|e| e.into_inner());
    eprintln!(
        "fuzz: {cases} cases (seed {seed:#x}) in {:.1} s: {} loaded, errors {:?}; largest peak heap growth {:.1} MiB, slowest case {:?} ({})",
        elapsed.as_secs_f64(),
        s.ok,
        s.errors,
        s.max_peak as f64 / (1 << 20) as f64,
        s.max_time,
        s.slowest,
    );
    let _ = std::fs::remove_dir_all(&root);
    if let Err(e) = result {
        panic!("{e}");
    }
}
