//! Replays every committed fuzz input (`fuzz/corpus/<target>/*`: hand-made seeds and
//! minimised crashers) through its target's property, so that `cargo test --workspace` keeps
//! them fixed without a fuzzer or a nightly toolchain. See `docs/fuzzing.md`.

use std::fs;
use std::panic;
use std::path::{Path, PathBuf};

use lucent_tests::fuzz_props::TARGETS;

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz")
}

fn sorted_entries(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .collect();
    files.sort();
    files
}

/// One test per target, so that a failure names the target; each replays the whole corpus
/// and reports every failing file, not just the first.
fn replay(target: &str) {
    let (_, property) = TARGETS
        .iter()
        .find(|(name, _)| *name == target)
        .unwrap_or_else(|| panic!("no property for {target}"));
    let files = sorted_entries(&fuzz_dir().join("corpus").join(target));
    assert!(!files.is_empty(), "the corpus of {target} is empty");
    let mut failures = Vec::new();
    for file in &files {
        let data = fs::read(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        if panic::catch_unwind(|| property(&data)).is_err() {
            failures.push(file.display().to_string());
        }
    }
    assert!(
        failures.is_empty(),
        "{target}: {} of {} corpus files fail:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

#[test]
fn cache_query_matches_exhaustive() {
    replay("cache_query_matches_exhaustive");
}

#[test]
fn table_lookup_finite() {
    replay("table_lookup_finite");
}

#[test]
fn scene_parse_never_panics() {
    replay("scene_parse_never_panics");
}

#[test]
fn obj_load_never_panics() {
    replay("obj_load_never_panics");
}

#[test]
fn ply_load_never_panics() {
    replay("ply_load_never_panics");
}

#[test]
fn gltf_load_never_panics() {
    replay("gltf_load_never_panics");
}

#[test]
fn raster_triangle_in_bounds() {
    replay("raster_triangle_in_bounds");
}

#[test]
fn shadow_rays_match_brute_force() {
    replay("shadow_rays_match_brute_force");
}

#[test]
fn convexity_is_sound() {
    replay("convexity_is_sound");
}

#[test]
fn texture_load_never_panics() {
    replay("texture_load_never_panics");
}

#[test]
fn exr_tile_read_never_panics() {
    replay("exr_tile_read_never_panics");
}

#[test]
fn samples_ply_read_never_panics() {
    replay("samples_ply_read_never_panics");
}

#[test]
fn crops_match_the_whole_render() {
    replay("crops_match_the_whole_render");
}

/// Every fuzz target has a property and a corpus, and every corpus a target: a target added
/// without its replay (or a misspelt directory) fails here.
#[test]
fn targets_corpora_and_properties_agree() {
    let dir = fuzz_dir();
    let stem = |p: &PathBuf| {
        p.file_stem()
            .and_then(|s| s.to_str())
            .expect("UTF-8 name")
            .to_string()
    };
    let mut targets: Vec<String> = sorted_entries(&dir.join("fuzz_targets"))
        .iter()
        .map(stem)
        .collect();
    let mut corpora: Vec<String> = sorted_entries(&dir.join("corpus"))
        .iter()
        .map(stem)
        .collect();
    let mut properties: Vec<String> = TARGETS.iter().map(|(n, _)| n.to_string()).collect();
    targets.sort();
    corpora.sort();
    properties.sort();
    assert_eq!(targets, properties, "fuzz_targets/ vs TARGETS");
    assert_eq!(corpora, properties, "corpus/ vs TARGETS");
    // The fuzz targets are thin wrappers stating their property on their first line.
    for name in &targets {
        let path = dir.join("fuzz_targets").join(format!("{name}.rs"));
        let text = fs::read_to_string(&path).expect("fuzz target source");
        assert!(
            text.starts_with("//! Property: "),
            "{name}.rs must start with a `//! Property: …` line"
        );
        assert!(
            text.contains(&format!("lucent_tests::fuzz_props::{name}(data)")),
            "{name}.rs must call lucent_tests::fuzz_props::{name}"
        );
    }
}

/// The scene-parser seeds are copies of the shipped scenes (`fuzz/make_seeds.py`); a scene
/// edited without re-running the script would leave the fuzzer starting from a stale file.
#[test]
fn scene_seeds_are_the_shipped_scenes() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let seeds = fuzz_dir().join("corpus/scene_parse_never_panics");
    for name in ["default", "sphere-shadow", "textured-mfp", "burley-marble"] {
        let scene = fs::read(scenes.join(format!("{name}.toml"))).expect("shipped scene");
        let seed = fs::read(seeds.join(format!("seed-{name}.toml"))).expect("seed");
        assert!(
            scene == seed,
            "fuzz seed for scenes/{name}.toml is stale: run `python3 fuzz/make_seeds.py`"
        );
    }
}
