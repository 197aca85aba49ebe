//! Loading a glTF file whose referenced files were fetched beforehand (as the web page does):
//! the same scene as from disk, the same refusals, and a typed error for a file not fetched.

use manylight_scene::{
    FetchedFiles, LoadOptions, ReferencedFile, SceneError, load_gltf, load_gltf_fetched, referenced_files,
};
use std::path::{Path, PathBuf};

fn asset(name: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets")).join(name)
}

/// Fetches (reads) `path` and every file it refers to, as the page fetches them over HTTP.
fn fetch_all(path: &Path) -> (Vec<u8>, FetchedFiles, Vec<ReferencedFile>) {
    let bytes = std::fs::read(path).expect("read the asset");
    let referenced = referenced_files(path, &bytes, &LoadOptions::default()).expect("list its files");
    let mut files = FetchedFiles::new();
    for file in &referenced {
        let folder = path.parent().expect("a folder");
        files.insert(
            file.name.clone(),
            std::fs::read(folder.join(&file.name)).expect("read a referenced file"),
        );
    }
    (bytes, files, referenced)
}

#[test]
fn a_fetched_gltf_loads_as_it_does_from_disk() {
    let path = asset("BoxTextured/BoxTextured.gltf");
    let (bytes, files, referenced) = fetch_all(&path);
    let names: Vec<&str> = referenced.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["BoxTextured0.bin", "CesiumLogoFlat.png"]);
    let fetched = load_gltf_fetched(&path, &bytes, &files, &LoadOptions::default()).expect("load fetched");
    let disk = load_gltf(&path, &LoadOptions::default()).expect("load from disk");
    assert_eq!(fetched.meshes.len(), disk.meshes.len());
    assert_eq!(fetched.instances.len(), disk.instances.len());
    for (a, b) in fetched.meshes.iter().zip(&disk.meshes) {
        assert_eq!(a.vertices, b.vertices);
        assert_eq!(a.indices, b.indices);
    }
    let texture = |s: &manylight_scene::Scene| s.materials[0].base_color_texture.clone().expect("textured");
    assert_eq!(texture(&fetched).image.rgba8, texture(&disk).image.rgba8);
}

#[test]
fn a_glb_refers_to_no_file() {
    let path = asset("DamagedHelmet/DamagedHelmet.glb");
    let (bytes, files, referenced) = fetch_all(&path);
    assert!(referenced.is_empty() && files.is_empty());
    let scene = load_gltf_fetched(&path, &bytes, &files, &LoadOptions::default()).expect("load");
    assert!(!scene.meshes.is_empty());
}

#[test]
fn a_file_that_was_not_fetched_is_named_in_a_typed_error() {
    let path = asset("BoxTextured/BoxTextured.gltf");
    let (bytes, _, _) = fetch_all(&path);
    // The buffer was fetched, the image was not.
    let mut files = FetchedFiles::new();
    files.insert("BoxTextured0.bin", std::fs::read(asset("BoxTextured/BoxTextured0.bin")).expect("read"));
    let err = load_gltf_fetched(&path, &bytes, &files, &LoadOptions::default()).unwrap_err();
    assert!(matches!(&err, SceneError::ReferencedFile { what, .. } if what == "image 0"), "{err:?}");
    assert!(err.to_string().contains("CesiumLogoFlat.png"), "{err}");
}

#[test]
fn uris_leaving_the_folder_are_refused_before_anything_is_fetched() {
    let path = Path::new("scenes/box.gltf");
    for uri in
        ["../secret.bin", "/etc/passwd", "https://example.com/x.bin", "file:///x.bin", "a%2F..%2F..%2Fx"]
    {
        let json = format!(r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":4,"uri":"{uri}"}}]}}"#);
        let err = referenced_files(path, json.as_bytes(), &LoadOptions::default()).unwrap_err();
        assert!(
            matches!(
                err,
                SceneError::UriOutsideFolder { .. }
                    | SceneError::ExternalUri { .. }
                    | SceneError::BadUri { .. }
            ),
            "{uri}: {err:?}"
        );
    }
    // Percent escapes are decoded into the name; `data:` URIs need no fetch.
    let json = r#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":1,"uri":"data:,A"},{"byteLength":4,"uri":"sub/my%20file.bin"}]}"#;
    let files = referenced_files(path, json.as_bytes(), &LoadOptions::default()).expect("valid");
    assert_eq!(files, [ReferencedFile { uri: "sub/my%20file.bin".into(), name: "sub/my file.bin".into() }]);
}

#[test]
fn fetched_bytes_count_against_the_file_budget() {
    let path = asset("BoxTextured/BoxTextured.gltf");
    let (bytes, files, _) = fetch_all(&path);
    let options = LoadOptions { max_json_bytes: 100, ..LoadOptions::default() };
    let err = load_gltf_fetched(&path, &bytes, &files, &options).unwrap_err();
    assert!(matches!(err, SceneError::OverBudget { option: "max_json_bytes", .. }), "{err:?}");
}
