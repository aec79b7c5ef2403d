//! Every loader on mutated bytes of a small corpus: meshes (OBJ, ASCII and
//! binary PLY from `tests/corpus`), scene files (`tests/corpus/scene.json`),
//! glTF scenes (`square.gltf` with its buffer embedded, `square.glb`),
//! render parts and HDR images (EXR and PFM, written fresh by the code
//! under test). Each input gives a result or an error that names the file,
//! never a panic. A bounded run: 1000 cases per loader by default (about a second),
//! `PROPTEST_CASES=N` for a longer one.
use std::path::{Path, PathBuf};

use proptest::prelude::*;
use treelet::render::image_io::{self, HdrImage};
use treelet::render::parts::{self, PartInfo};

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(1000)
}

fn corpus(ext: &[&str]) -> Vec<(String, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| ext.contains(&image_io::extension(p).as_str()))
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap()))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no {ext:?} file in the corpus");
    files
}

/// A part and two images, written by the code under test, as seeds (once).
fn written_corpus() -> &'static [(String, Vec<u8>)] {
    static SEEDS: std::sync::OnceLock<Vec<(String, Vec<u8>)>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(write_seeds)
}

fn write_seeds() -> Vec<(String, Vec<u8>)> {
    let dir = std::env::temp_dir().join(format!("treelet-fuzz-seeds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (w, h) = (3u32, 2u32);
    let sums: Vec<[f32; 4]> = (0..w * h).map(|i| [i as f32, 0.5, 2.0, 1.25]).collect();
    let info = PartInfo {
        scene: "cornell".into(),
        scene_hash: "0123456789abcdef".into(),
        width: w,
        height: h,
        seed: 7,
        integrator: "nee".into(),
        sampler: "sobol".into(),
        samples: 4..12,
        planned_end: 16,
    };
    parts::write_part(&dir.join("part.exr"), &info, &sums).unwrap();
    let image = HdrImage { width: w, height: h, pixels: (0..w * h).map(|i| [i as f32 * 0.1, 0.2, 0.3]).collect() };
    image_io::write(&dir.join("image.exr"), &image).unwrap();
    image_io::write(&dir.join("image.pfm"), &image).unwrap();
    let out =
        ["part.exr", "image.exr", "image.pfm"].map(|n| (n.to_string(), std::fs::read(dir.join(n)).unwrap())).to_vec();
    let _ = std::fs::remove_dir_all(&dir);
    out
}

/// Applies `edits` (position, byte, kind) to `bytes`: overwrite, insert,
/// delete, or truncate there.
fn mutate(mut bytes: Vec<u8>, edits: &[(usize, u8, u8)]) -> Vec<u8> {
    for &(at, byte, kind) in edits {
        if bytes.is_empty() {
            bytes.push(byte);
            continue;
        }
        let at = at % bytes.len();
        match kind % 4 {
            0 => bytes[at] = byte,
            1 => bytes.insert(at, byte),
            2 => {
                bytes.remove(at);
            }
            _ => bytes.truncate(at),
        }
    }
    bytes
}

/// Writes a mutation of `files[which]` and runs `load` on it: no panic, and
/// an error names the file.
fn check<T>(
    files: &[(String, Vec<u8>)],
    which: usize,
    edits: &[(usize, u8, u8)],
    load: impl Fn(&Path) -> anyhow::Result<T> + std::panic::RefUnwindSafe,
) -> Result<(), TestCaseError> {
    let (name, bytes) = &files[which % files.len()];
    let dir = std::env::temp_dir().join(format!("treelet-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // One file per thread: the tests run side by side.
    let path: PathBuf = dir.join(format!("m-{:?}-{name}", std::thread::current().id()).replace(['(', ')'], ""));
    std::fs::write(&path, mutate(bytes.clone(), edits)).unwrap();
    let result = std::panic::catch_unwind(|| load(&path));
    prop_assert!(result.is_ok(), "the loader panicked on a mutation of {}", name);
    if let Ok(Err(e)) = result {
        prop_assert!(format!("{e:#}").contains(&path.display().to_string()), "error `{e:#}` does not name the file");
    }
    Ok(())
}

fn edits() -> impl Strategy<Value = Vec<(usize, u8, u8)>> {
    proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn mutated_meshes_never_panic(which in 0usize..16, edits in edits()) {
        check(&corpus(&["obj", "ply"]), which, &edits, treelet::scene::mesh::load)?;
    }

    #[test]
    fn mutated_scene_files_never_panic(edits in edits()) {
        check(&corpus(&["json"]), 0, &edits, treelet::scene::file::load)?;
    }

    #[test]
    fn mutated_gltf_files_never_panic(which in 0usize..2, edits in edits()) {
        check(&corpus(&["gltf", "glb"]), which, &edits, treelet::scene::gltf::load)?;
    }

    #[test]
    fn mutated_parts_never_panic(edits in edits()) {
        check(&written_corpus()[..1], 0, &edits, parts::read_part)?;
    }

    #[test]
    fn mutated_images_never_panic(which in 0usize..2, edits in edits()) {
        check(&written_corpus()[1..], which, &edits, image_io::read_hdr)?;
    }
}

/// Inputs the libFuzzer targets (`tests/fuzz`) found a fault with, kept once
/// fixed: `corpus/regressions/<target>/`, each read as its target reads it
/// (no panic; an error names the file). The first: a relative texture
/// index past the start (`f 1/-11`), which overflowed in tobj's bounds
/// check where overflow is checked.
#[test]
fn fuzz_findings_stay_fixed() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus/regressions");
    let mut seen = 0;
    for target in std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()) {
        let kind = target.file_name().unwrap().to_string_lossy().into_owned();
        for file in std::fs::read_dir(&target).unwrap().map(|e| e.unwrap().path()) {
            let mut bytes = std::fs::read(&file).unwrap();
            let case = |name: &str, bytes: Vec<u8>| vec![(name.to_string(), bytes)];
            let result = match kind.as_str() {
                "obj" => check(&case("input.obj", bytes), 0, &[], treelet::scene::mesh::load),
                "ply" => check(&case("input.ply", bytes), 0, &[], treelet::scene::mesh::load),
                "scene_file" => check(&case("scene.json", bytes), 0, &[], treelet::scene::file::load),
                "gltf" => check(&case("scene.gltf", bytes), 0, &[], treelet::scene::gltf::load),
                "glb" => check(&case("scene.glb", bytes), 0, &[], treelet::scene::gltf::load),
                "part" => check(&case("part.exr", bytes), 0, &[], parts::read_part),
                "hdr_image" => {
                    assert!(!bytes.is_empty(), "{}: an hdr_image input starts with its kind byte", file.display());
                    let name = if bytes.remove(0) & 1 == 0 { "image.exr" } else { "image.pfm" };
                    check(&case(name, bytes), 0, &[], image_io::read_hdr)
                }
                other => panic!("{}: no fuzz target `{other}`", file.display()),
            };
            result.unwrap_or_else(|e| panic!("{}: {e}", file.display()));
            seen += 1;
        }
    }
    assert!(seen > 0, "no finding in {}", dir.display());
}
