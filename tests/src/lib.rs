//! Helpers shared by the integration tests.
use std::sync::{Arc, OnceLock};

use treelet::runtime::gpu::GpuContext;

/// The GPU context for tests. A missing adapter fails the test (install
/// lavapipe: `scripts/setup`), unless `TREELET_TESTS_WITHOUT_GPU=1` asks to
/// skip GPU tests on a machine without Vulkan (never under `CI`); a skip
/// prints its reason.
pub fn gpu() -> Option<Arc<GpuContext>> {
    static CTX: OnceLock<Result<Arc<GpuContext>, String>> = OnceLock::new();
    match CTX.get_or_init(|| GpuContext::new().map_err(|e| format!("{e:#}"))) {
        Ok(ctx) => Some(ctx.clone()),
        Err(e) if std::env::var_os("CI").is_some() => panic!("CI is set and no GPU adapter is usable: {e}"),
        Err(e) if std::env::var("TREELET_TESTS_WITHOUT_GPU").is_ok_and(|v| v == "1") => {
            eprintln!("SKIPPED (no GPU adapter, TREELET_TESTS_WITHOUT_GPU=1): {e}");
            None
        }
        Err(e) => panic!("no GPU adapter is usable ({e}): install lavapipe (sh scripts/setup), or set TREELET_TESTS_WITHOUT_GPU=1 to skip GPU tests"),
    }
}

use rand::Rng;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::bvh::lbvh::{self, Bvh};
use treelet::bvh::validate::validate;
use treelet_core::Sphere;

/// A fresh random seed, printed so that a failure can be replayed.
pub fn fresh_seed() -> u64 {
    // TREELET_TEST_SEED replays a failure a run printed.
    let seed = match std::env::var("TREELET_TEST_SEED") {
        Ok(s) => s.parse().expect("TREELET_TEST_SEED must be an unsigned integer"),
        Err(_) => rand::rng().random(),
    };
    eprintln!("seed {seed}");
    seed
}

/// Builds on the CPU runner, checks the tree with the independent validator.
pub fn build_cpu_checked(spheres: &[Sphere], what: &str) -> Bvh {
    treelet::scene::validate_spheres(spheres).unwrap();
    let (c, _) = lbvh::build(&mut CpuBackend::new(), spheres).unwrap();
    let v = validate(spheres, &c.nodes, &c.parents, &c.prim_indices);
    assert!(v.is_valid(), "{what}: CPU tree invalid: {:?}", v.errors);
    assert_fully_sorted(spheres, &c, what);
    c
}

/// The build's order is the stable sort of every bit of the primitives'
/// Morton keys, recomputed here from the spheres: keys in order, equal keys
/// by primitive index, every primitive once. (The sort takes its high
/// digits first and settles ties after: this holds it to the full order.)
pub fn assert_fully_sorted(spheres: &[Sphere], bvh: &Bvh, what: &str) {
    use treelet_core::construct::morton::MortonFrame;
    let frame = MortonFrame::new(&bvh.centroid_bounds);
    let mut seen = vec![false; spheres.len()];
    for (i, (&key, &prim)) in bvh.sorted_keys.iter().zip(&bvh.prim_indices).enumerate() {
        let centroid = spheres[prim as usize].aabb().centroid();
        assert_eq!(key, frame.code(centroid), "{what}: sorted key {i} is not primitive {prim}'s code");
        assert!(!std::mem::replace(&mut seen[prim as usize], true), "{what}: primitive {prim} sorted twice");
        if i > 0 {
            let before = (bvh.sorted_keys[i - 1], bvh.prim_indices[i - 1]);
            assert!(before < (key, prim), "{what}: keys {} and {i} out of order: {before:?} then {:?}", i - 1, (key, prim));
        }
    }
}

/// Builds on the GPU and on the CPU runner; requires identical keys, order,
/// topology and boxes, and a valid tree. Without a GPU (outside CI), checks
/// the CPU tree alone and says so.
pub fn compare_builds(spheres: &[Sphere], what: &str) {
    let c = build_cpu_checked(spheres, what);
    let Some(ctx) = gpu() else { return };
    let (g, _) = lbvh::build(&mut GpuBackend::new(ctx), spheres).unwrap();
    assert_eq!(g.centroid_bounds, c.centroid_bounds, "{what}: centroid bounds");
    if let Some(i) = (0..c.sorted_keys.len()).find(|&i| g.sorted_keys[i] != c.sorted_keys[i]) {
        panic!("{what}: sorted keys differ first at {i}: gpu {:#x} cpu {:#x}", g.sorted_keys[i], c.sorted_keys[i]);
    }
    assert_eq!(g.prim_indices, c.prim_indices, "{what}: sorted primitive order");
    if let Some(i) = (0..c.nodes.len()).find(|&i| g.nodes[i] != c.nodes[i]) {
        panic!("{what}: node {i} differs: gpu {:?} cpu {:?}", g.nodes[i], c.nodes[i]);
    }
    assert_eq!(g.parents, c.parents, "{what}: parents");
    let v = validate(spheres, &g.nodes, &g.parents, &g.prim_indices);
    assert!(v.is_valid(), "{what}: GPU tree invalid: {:?}", v.errors);
}
