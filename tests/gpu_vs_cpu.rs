//! GPU results against the CPU run of the same kernel functions, on fresh
//! random inputs: integer stages bit for bit, boxes exactly (min and max are
//! exact in floating point), plus invariants that do not use the builder.
use rand::{Rng, SeedableRng};
use treelet::backend::Backend;
use treelet::cpu_runner::CpuBackend;
use treelet::gpu::GpuBackend;
use treelet::scene::random_spheres;
use treelet_tests::{compare_builds, gpu};

#[test]
fn lbvh_matches_cpu_on_random_scenes() {
    let seed = treelet_tests::fresh_seed();
    for n in [1usize, 2, 3, 7, 8, 1000, 4096, 30_000] {
        compare_builds(&random_spheres(n, seed ^ n as u64), &format!("random:{n}:{seed}"));
    }
}

#[test]
fn sort_matches_cpu_and_std_on_random_keys() {
    let Some(ctx) = gpu() else { return };
    let seed = treelet_tests::fresh_seed();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    for n in [1u32, 255, 256, 2049, 70_000] {
        // Few distinct high bits, so that many keys tie on some passes.
        let keys: Vec<u64> = (0..n).map(|_| rng.random::<u64>() >> rng.random_range(0..64)).collect();
        let values: Vec<u32> = (0..n).collect();
        let g = run_sort(&mut GpuBackend::new(ctx.clone()), &keys, &values);
        let c = run_sort(&mut CpuBackend::new(), &keys, &values);
        let mut expected: Vec<(u64, u32)> = keys.iter().copied().zip(values.iter().copied()).collect();
        expected.sort_by_key(|&(k, _)| k); // stable, like the radix sort
        let (ek, ev): (Vec<u64>, Vec<u32>) = expected.into_iter().unzip();
        assert_eq!(c.0, ek, "cpu keys, n = {n}");
        assert_eq!(c.1, ev, "cpu values (stability), n = {n}");
        assert_eq!(g.0, ek, "gpu keys, n = {n}");
        assert_eq!(g.1, ev, "gpu values (stability), n = {n}");
    }
}

fn run_sort<B: Backend>(b: &mut B, keys: &[u64], values: &[u32]) -> (Vec<u64>, Vec<u32>) {
    let n = keys.len() as u32;
    let kb = b.upload("keys", keys).unwrap();
    let vb = b.upload("values", values).unwrap();
    let (k, v) = treelet::sort::radix_sort(b, &kb, &vb, n, 64).unwrap();
    (b.read(&k, n as usize).unwrap(), b.read(&v, n as usize).unwrap())
}

/// Builds on one GPU backend reuse its buffers; stale contents (the fit's
/// arrival counters above all) must never leak into the next build.
#[test]
fn repeated_builds_on_one_backend_stay_correct() {
    let Some(ctx) = gpu() else { return };
    let seed = treelet_tests::fresh_seed();
    let mut backend = GpuBackend::new(ctx);
    for (k, n) in [5000usize, 5000, 5000, 777, 5000].into_iter().enumerate() {
        let spheres = random_spheres(n, seed.wrapping_add(k as u64));
        let (g, _) = treelet::lbvh::build(&mut backend, &spheres).unwrap();
        let c = treelet_tests::build_cpu_checked(&spheres, "reuse");
        assert_eq!(g.nodes, c.nodes, "build {k} (n = {n}) on a reused backend differs from the CPU");
        assert_eq!(g.prim_indices, c.prim_indices, "build {k}");
    }
}

/// `zeroed` must clear a pooled buffer that held data in an earlier build.
#[test]
fn zeroed_clears_reused_buffers() {
    let Some(ctx) = gpu() else { return };
    let mut b = GpuBackend::new(ctx);
    b.begin_build();
    let dirty = b.upload("probe", &[0xdead_beefu32; 1000]).unwrap();
    assert_eq!(b.read::<u32>(&dirty, 1000).unwrap(), vec![0xdead_beef; 1000]);
    b.begin_build();
    let clean = b.zeroed("probe", 4000).unwrap();
    assert!(clean == dirty, "the pool should hand out the same buffer again");
    assert_eq!(b.read::<u32>(&clean, 1000).unwrap(), vec![0; 1000]);
}
