//! GPU results against the CPU run of the same kernel functions, on fresh
//! random inputs: integer stages bit for bit, boxes exactly (min and max are
//! exact in floating point), plus invariants that do not use the builder.
use rand::{Rng, SeedableRng};
use treelet::runtime::backend::Backend;
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::scene::random_spheres;
use treelet::bvh::sort::SortTiles;
use treelet_tests::{compare_builds, gpu};

#[test]
fn lbvh_matches_cpu_on_random_scenes() {
    let seed = treelet_tests::fresh_seed();
    for n in [1usize, 2, 3, 7, 8, 1000, 4096, 30_000] {
        compare_builds(&random_spheres(n, seed ^ n as u64), &format!("random:{n}:{seed}"));
    }
}

/// The build sorts its keys by their high digits first and settles the
/// ties after (`treelet_core::construct::sort::ties`), or sorts every digit
/// when a run of ties is too long: both give the full sort's order
/// (`compare_builds` checks it against keys recomputed on the host), on
/// spheres whose keys tie in short runs (three to a centre), and on a dense
/// cluster inside a huge scene, whose keys all share their high digits.
#[test]
fn lbvh_sorts_every_bit_with_short_and_long_runs_of_ties() {
    let seed = treelet_tests::fresh_seed();
    let mut triples = random_spheres(20_000, seed);
    for (k, s) in triples.iter_mut().enumerate() {
        s.center = [(k / 3 % 29) as f32 * 1.7, (k / 3 / 29 % 31) as f32 * 0.9, (k / 3 / 29 / 31) as f32 * 1.3];
    }
    // The longest run of keys tied in the digits sorted first, in the CPU build.
    let longest_run = |spheres: &[treelet_core::Sphere]| {
        let keys = treelet_tests::build_cpu_checked(spheres, "runs").sorted_keys;
        let low_bits = 8 * treelet_core::construct::sort::ties::first_high_digit(keys.len() as u32, 8);
        let (mut longest, mut run) = (1, 1);
        for w in keys.windows(2) {
            run = if w[0] >> low_bits == w[1] >> low_bits { run + 1 } else { 1 };
            longest = longest.max(run);
        }
        longest
    };
    use treelet_core::construct::sort::ties::MAX_TIE_RUN;
    assert!((2..=MAX_TIE_RUN).contains(&longest_run(&triples)), "runs of ties to settle");
    compare_builds(&triples, &format!("three spheres a centre, seed {seed}"));
    let mut room = random_spheres(3000, seed ^ 1);
    for s in room.iter_mut() {
        s.center = s.center.map(|c| c * 1e-3);
        s.radius *= 1e-3;
    }
    room.push(treelet_core::Sphere { center: [1e5, 0.0, 0.0], radius: 1e5 - 10.0, ..room[0] });
    room.push(treelet_core::Sphere { center: [-1e5, 0.0, 0.0], radius: 1e5 - 10.0, ..room[0] });
    assert!(longest_run(&room) > MAX_TIE_RUN, "a run too long to settle: every digit sorted");
    compare_builds(&room, &format!("a dense cluster in a huge room, seed {seed}"));
    compare_builds(&clustered_spheres(seed), &format!("5000 spheres on 7 centres, seed {seed}"));
}

/// Random spheres, `n` of them for each `n` of `sizes`, named by size and seed.
fn random_sphere_scenes(sizes: &[usize], seed: u64) -> Vec<(String, Vec<treelet_core::Sphere>)> {
    sizes.iter().map(|&n| (format!("random:{n}:{seed}"), random_spheres(n, seed ^ n as u64))).collect()
}

/// Many spheres on few distinct centres: long runs of equal keys.
fn clustered_spheres(seed: u64) -> Vec<treelet_core::Sphere> {
    let mut clustered = random_spheres(5000, seed);
    for (k, s) in clustered.iter_mut().enumerate() {
        s.center = [(k % 7) as f32; 3];
    }
    clustered
}

/// The agglomerative build (Apetrei 2014), plain and with its lowest levels
/// merged within subgroups, gives the radix tree plus fit's nodes and
/// parents bit for bit, on the GPU and on the CPU runner (at several
/// subgroup sizes), also where many Morton keys are equal.
#[test]
fn agglomerative_build_equals_radix_tree_and_fit() {
    use treelet::bvh::lbvh::{build_with, Hierarchy};
    let seed = treelet_tests::fresh_seed();
    let mut scenes = random_sphere_scenes(&[1, 2, 5, 1000, 40_000, 100_000], seed);
    scenes.push((format!("clustered, seed {seed}"), clustered_spheres(seed)));
    let gpu_ctx = gpu();
    for (what, spheres) in &scenes {
        let reference = build_with(&mut CpuBackend::new(), spheres, Hierarchy::RadixTreeThenFit).unwrap();
        let mut trees =
            vec![("cpu agglomerative", build_with(&mut CpuBackend::new(), spheres, Hierarchy::Agglomerative).unwrap())];
        // Merged within subgroups first, at the sizes devices have.
        for (how, size) in [("cpu by subgroups of 8", 8), ("cpu by subgroups of 32", 32), ("cpu by subgroups of 64", 64)] {
            let mut b = CpuBackend::with_subgroup_size(size);
            trees.push((how, build_with(&mut b, spheres, Hierarchy::AgglomerativeSubgroup).unwrap()));
        }
        if let Some(ctx) = &gpu_ctx {
            let mut b = GpuBackend::new(ctx.clone());
            trees.push(("gpu radix tree + fit", build_with(&mut b, spheres, Hierarchy::RadixTreeThenFit).unwrap()));
            trees.push(("gpu agglomerative", build_with(&mut b, spheres, Hierarchy::Agglomerative).unwrap()));
            trees.push(("gpu by subgroups", build_with(&mut b, spheres, Hierarchy::AgglomerativeSubgroup).unwrap()));
        }
        for (how, t) in &trees {
            assert_eq!(t.prim_indices, reference.prim_indices, "{what}, {how}: order");
            if let Some(i) = (0..reference.nodes.len()).find(|&i| t.nodes[i] != reference.nodes[i]) {
                panic!(
                    "{what}, {how}: node {i}: {:?}, radix tree + fit on the CPU: {:?}",
                    t.nodes[i], reference.nodes[i]
                );
            }
            assert_eq!(t.parents, reference.parents, "{what}, {how}: parents");
        }
        let v = treelet::bvh::validate::validate(spheres, &trees[0].1.nodes, &trees[0].1.parents, &trees[0].1.prim_indices);
        assert!(v.is_valid(), "{what}: agglomerative tree invalid: {:?}", v.errors);
    }
}

/// H-PLOC (`treelet_core::construct::hploc`): valid trees at every
/// subgroup size the CPU runner takes, on random spheres, runs of equal
/// keys, equal boxes and a terrain mesh; on the GPU, the CPU runner's nodes
/// and parents bit for bit at the GPU's subgroup size; and trees of lower
/// SAH than the LBVH's on the mesh (what the builder is for).
#[test]
fn hploc_matches_cpu_and_is_valid() {
    use treelet::bvh::lbvh::{build_primitives_with, Bvh, Hierarchy};
    use treelet::scene::primitives::Primitives;
    use treelet_core::construct::sah::{sah_cost, SahCosts};
    let seed = treelet_tests::fresh_seed();
    let mut sphere_scenes = random_sphere_scenes(&[1, 2, 3, 5, 33, 1000, 40_000, 100_000], seed);
    let mut clustered = clustered_spheres(seed);
    sphere_scenes.push((format!("clustered, seed {seed}"), clustered.clone()));
    for s in clustered.iter_mut() {
        s.radius = 1.0;
    }
    sphere_scenes.push(("equal spheres".into(), vec![clustered[0]; 3000]));
    let terrain = treelet::scene::model::terrain(60_000);
    let mut scenes: Vec<(String, Primitives)> =
        sphere_scenes.iter().map(|(w, s)| (w.clone(), Primitives::spheres(s))).collect();
    scenes.push(("terrain:60000".into(), Primitives::triangles(&terrain)));
    let build = |b: &mut dyn FnMut(Primitives) -> Bvh, prims| b(prims);
    let gpu_ctx = gpu();
    for (what, prims) in &scenes {
        let check = |t: &Bvh, how: &str| {
            let v = treelet::bvh::validate::validate_primitives(*prims, &t.nodes, &t.parents, &t.prim_indices);
            assert!(v.is_valid(), "{what}, {how}: invalid: {:?}", v.errors);
        };
        let cpu = |size: u32| {
            let mut b = CpuBackend::with_subgroup_size(size);
            build(&mut |p| build_primitives_with(&mut b, p, Hierarchy::Hploc).unwrap().0.read(&mut b).unwrap(), *prims)
        };
        for size in [4, 8, 16, 32, 64] {
            check(&cpu(size), &format!("cpu, subgroups of {size}"));
        }
        if let Some(ctx) = &gpu_ctx {
            let size = ctx.info.subgroup_min_size;
            assert_eq!(size, ctx.info.subgroup_max_size, "the GPU's subgroup size varies: compare by SAH instead");
            let mut b = GpuBackend::new(ctx.clone());
            let g = build_primitives_with(&mut b, *prims, Hierarchy::Hploc).unwrap().0.read(&mut b).unwrap();
            check(&g, "gpu");
            let c = cpu(size);
            assert_eq!(g.prim_indices, c.prim_indices, "{what}: order");
            if let Some(i) = (0..c.nodes.len()).find(|&i| g.nodes[i] != c.nodes[i]) {
                panic!("{what}: node {i}: gpu {:?}, cpu (subgroups of {size}) {:?}", g.nodes[i], c.nodes[i]);
            }
            assert_eq!(g.parents, c.parents, "{what}: parents");
        }
        if what.starts_with("terrain") {
            let mut b = CpuBackend::new();
            let lbvh = build_primitives_with(&mut b, *prims, Hierarchy::Agglomerative).unwrap().0.read(&mut b).unwrap();
            let (h, l) = (sah_cost(&cpu(32).nodes, SahCosts::KARRAS_AILA), sah_cost(&lbvh.nodes, SahCosts::KARRAS_AILA));
            assert!(h < 0.98 * l, "{what}: H-PLOC SAH {h} against the LBVH's {l}");
        }
    }
}

#[test]
fn sort_matches_cpu_and_std_on_random_keys() {
    let Some(ctx) = gpu() else { return };
    let seed = treelet_tests::fresh_seed();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    // Sizes around the tile (2048 keys) and many tiles, so that look-backs
    // cross several tiles.
    for n in [1u32, 255, 256, 2047, 2049, 6145, 70_000] {
        // Few distinct high bits, so that many keys tie on some passes.
        let keys: Vec<u64> = (0..n).map(|_| rng.random::<u64>() >> rng.random_range(0..64)).collect();
        check_sort(&ctx, &keys, 64, &format!("random, n = {n}, seed {seed}"));
    }
}

/// Keys whose high digits take few values, so that the sort by high
/// digits first leaves runs of ties of every length up to and past what one
/// invocation settles, across tiles and workgroups.
#[test]
fn sort_by_high_digits_settles_runs_of_ties() {
    let Some(ctx) = gpu() else { return };
    let seed = treelet_tests::fresh_seed();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    for (n, highs) in [(2u32, 1u64), (100, 40), (5000, 2500), (70_000, 30_000), (70_000, 2_000), (70_000, 60_000)] {
        // The digits sorted first take `highs` values; below them, few bits vary.
        let low_bits = 8 * treelet_core::construct::sort::ties::first_high_digit(n, 8);
        let keys: Vec<u64> = (0..n)
            .map(|_| rng.random_range(0..highs) << low_bits | rng.random_range(0..8u64) << (low_bits - 3) | rng.random::<u8>() as u64)
            .collect();
        check_sort(&ctx, &keys, 63, &format!("{n} keys, {highs} high values, seed {seed}"));
    }
}

/// The shapes a radix sort gets wrong: all keys equal (one digit takes
/// every key of every tile), already sorted, reversed, and keys of fewer
/// bits than the sort's passes cover or more than it sorts.
#[test]
fn sort_handles_equal_sorted_and_reversed_keys() {
    let Some(ctx) = gpu() else { return };
    let seed = treelet_tests::fresh_seed();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let n = 50_000u64;
    let random: Vec<u64> = (0..n).map(|_| rng.random()).collect();
    let mut sorted = random.clone();
    sorted.sort();
    let reversed: Vec<u64> = sorted.iter().rev().copied().collect();
    check_sort(&ctx, &vec![0x1234_5678_9abc_def0; n as usize], 64, "all equal");
    check_sort(&ctx, &vec![0; 4099], 64, "all zero");
    check_sort(&ctx, &sorted, 64, &format!("sorted, seed {seed}"));
    check_sort(&ctx, &reversed, 64, &format!("reversed, seed {seed}"));
    check_sort(&ctx, &(0..n).map(|k| (n - k) << 40).collect::<Vec<_>>(), 64, "reversed, low bits zero");
    let low: Vec<u64> = random.iter().map(|k| k & ((1 << 30) - 1)).collect();
    check_sort(&ctx, &low, 30, &format!("30-bit keys, seed {seed}"));
    check_sort(&ctx, &low, 63, &format!("30-bit keys sorted on 63 bits, seed {seed}"));
}

/// Many sorts on the GPU against std's stable sort: look-back across
/// thousands of tiles, under whatever scheduling the device does. On a CPU
/// adapter (lavapipe in CI: minutes for the full set) fewer and smaller
/// sorts, which still cross dozens of tiles per pass.
#[test]
fn sort_stress_on_large_inputs() {
    let Some(ctx) = gpu() else { return };
    let seed = treelet_tests::fresh_seed();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut b = GpuBackend::new(ctx);
    let (trials, sizes) =
        if b.runs_on_cpu() { (6, [70_000u32, 150_000, 300_000]) } else { (40, [70_000, 1_000_000, 4_000_000]) };
    for trial in 0..trials {
        let n = sizes[trial % 3];
        let keys: Vec<u64> = (0..n).map(|_| rng.random::<u64>() >> rng.random_range(0..64)).collect();
        let values: Vec<u32> = (0..n).collect();
        b.begin_build();
        let kinds: &[SortTiles] = if treelet::bvh::sort::multisplit_runs_on(&b) {
            &[SortTiles::Large, SortTiles::Small, SortTiles::Multisplit, SortTiles::MultisplitSmall, SortTiles::MultisplitMedium]
        } else {
            &[SortTiles::Large, SortTiles::Small]
        };
        let tiles = kinds[(trial / 3) % kinds.len()];
        let g = run_sort(&mut b, &keys, &values, 64, tiles);
        let mut expected: Vec<(u64, u32)> = keys.into_iter().zip(values).collect();
        expected.sort_by_key(|&(k, _)| k);
        let (ek, ev): (Vec<u64>, Vec<u32>) = expected.into_iter().unzip();
        assert!(g.0 == ek && g.1 == ev, "trial {trial}, n = {n}, {tiles:?} tiles, seed {seed}");
    }
}

/// Sorts `keys` (values: their indices) by their low `key_bits` bits with
/// large tiles, small tiles and tiles ranked by subgroups (the CPU runner at
/// subgroup sizes 32 and 64; the GPU where its subgroups are large
/// enough), on the GPU and the CPU runner, against std's stable sort.
fn check_sort(ctx: &std::sync::Arc<treelet::runtime::gpu::GpuContext>, keys: &[u64], key_bits: u32, what: &str) {
    let n = keys.len();
    let values: Vec<u32> = (0..n as u32).collect();
    let mask = if key_bits >= 64 { u64::MAX } else { (1u64 << key_bits) - 1 };
    let mut expected: Vec<(u64, u32)> = keys.iter().copied().zip(values.iter().copied()).collect();
    expected.sort_by_key(|&(k, _)| k & mask); // stable, like the radix sort
    let (ek, ev): (Vec<u64>, Vec<u32>) = expected.into_iter().unzip();
    // Without look-back (lavapipe) the GPU sorts with large tiles only.
    let look_back_on_gpu = GpuBackend::new(ctx.clone()).look_back_works();
    for size in [32, 64] {
        for tiles in [SortTiles::Multisplit, SortTiles::MultisplitSmall, SortTiles::MultisplitMedium] {
            let c = run_sort(&mut CpuBackend::with_subgroup_size(size), keys, &values, key_bits, tiles);
            assert!(c.0 == ek, "cpu keys, {tiles:?} tiles, subgroups of {size}, {what}");
            assert!(c.1 == ev, "cpu values (stability), {tiles:?} tiles, subgroups of {size}, {what}");
        }
    }
    let multisplit_on_gpu = treelet::bvh::sort::multisplit_runs_on(&GpuBackend::new(ctx.clone()));
    for tiles in
        [SortTiles::Small, SortTiles::Large, SortTiles::Multisplit, SortTiles::MultisplitSmall, SortTiles::MultisplitMedium]
    {
        let multisplit = matches!(tiles, SortTiles::Multisplit | SortTiles::MultisplitSmall | SortTiles::MultisplitMedium);
        if !multisplit {
            let c = run_sort(&mut CpuBackend::new(), keys, &values, key_bits, tiles);
            assert!(c.0 == ek, "cpu keys, {tiles:?} tiles, {what}");
            assert!(c.1 == ev, "cpu values (stability), {tiles:?} tiles, {what}");
        }
        if (tiles == SortTiles::Small && !look_back_on_gpu) || (multisplit && !multisplit_on_gpu) {
            continue;
        }
        let g = run_sort(&mut GpuBackend::new(ctx.clone()), keys, &values, key_bits, tiles);
        assert!(g.0 == ek, "gpu keys, {tiles:?} tiles, {what}");
        assert!(g.1 == ev, "gpu values (stability), {tiles:?} tiles, {what}");
    }
    check_high_first(ctx, keys, key_bits, (&ek, &ev), what);
}

/// The sort by high digits first, then ties ([`treelet::bvh::sort::radix_sort_high_first`]),
/// on the CPU runner and the GPU, against the expected order `(ek, ev)`: the
/// same, or `None` exactly where a run of keys tied in the high digits is
/// longer than one invocation settles (counted here from the expected order).
fn check_high_first(
    ctx: &std::sync::Arc<treelet::runtime::gpu::GpuContext>,
    keys: &[u64],
    key_bits: u32,
    (ek, ev): (&[u64], &[u32]),
    what: &str,
) {
    use treelet_core::construct::sort::ties::MAX_TIE_RUN;
    let passes = key_bits.div_ceil(8);
    let sorted = |k: u64| if passes >= 8 { k } else { k & ((1u64 << (8 * passes)) - 1) };
    let first = treelet_core::construct::sort::ties::first_high_digit(keys.len() as u32, passes);
    let high = |k: u64| sorted(k) >> (8 * first);
    let mut longest = 1;
    let mut run = 1;
    for w in ek.windows(2) {
        run = if high(w[0]) == high(w[1]) { run + 1 } else { 1 };
        longest = longest.max(run);
    }
    let settles = first == 0 || longest <= MAX_TIE_RUN;
    let values: Vec<u32> = (0..keys.len() as u32).collect();
    let check = |got: Option<(Vec<u64>, Vec<u32>)>, on: &str| match got {
        Some((k, v)) => {
            assert!(settles, "{on}: settled a run of {longest} ties, {what}");
            assert!(k == ek && v == ev, "{on}: high digits first, then ties, {what}");
        }
        None => assert!(!settles, "{on}: gave up on runs of at most {longest} ties, {what}"),
    };
    check(run_sort_high_first(&mut CpuBackend::new(), keys, &values, key_bits, SortTiles::Large), "cpu");
    check(run_sort_high_first(&mut CpuBackend::with_subgroup_size(32), keys, &values, key_bits, SortTiles::Multisplit), "cpu, ranked by subgroups");
    check(run_sort_high_first(&mut GpuBackend::new(ctx.clone()), keys, &values, key_bits, SortTiles::Auto), "gpu");
}

fn run_sort_high_first<B: Backend>(
    b: &mut B,
    keys: &[u64],
    values: &[u32],
    key_bits: u32,
    tiles: SortTiles,
) -> Option<(Vec<u64>, Vec<u32>)> {
    let n = keys.len() as u32;
    let kb = b.upload("keys", keys).unwrap();
    let vb = b.upload("values", values).unwrap();
    let (k, v) = treelet::bvh::sort::radix_sort_high_first_tiled(b, &kb, &vb, n, key_bits, tiles).unwrap()?;
    Some((b.read(&k, n as usize).unwrap(), b.read(&v, n as usize).unwrap()))
}

fn run_sort<B: Backend>(
    b: &mut B,
    keys: &[u64],
    values: &[u32],
    key_bits: u32,
    tiles: SortTiles,
) -> (Vec<u64>, Vec<u32>) {
    let n = keys.len() as u32;
    let kb = b.upload("keys", keys).unwrap();
    let vb = b.upload("values", values).unwrap();
    let (k, v) = treelet::bvh::sort::radix_sort_tiled(b, &kb, &vb, n, key_bits, tiles).unwrap();
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
        let (g, _) = treelet::bvh::lbvh::build(&mut backend, &spheres).unwrap();
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

/// Subgroup operations on the GPU against their emulation on the CPU runner:
/// the multisplit ranking kernel (a ballot of the lanes with keys, then one
/// per bit of the digit) on fresh random keys, at counts that cross
/// subgroups and workgroups, run on the CPU at the subgroup size the GPU
/// ran with; and, independently of both, every rank and count counted by
/// hand over the subgroup's keys.
#[test]
fn subgroup_multisplit_matches_the_cpu_emulation() {
    use treelet::runtime::kernels::Kernel;
    use treelet_core::geometry::buffers::SortParams;
    use treelet_core::gpu::workgroup::{groups_for, WORKGROUP_SIZE};
    fn run<B: Backend>(b: &mut B, keys: &[u64], pass: u32) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
        let n = keys.len() as u32;
        let groups = groups_for(n, WORKGROUP_SIZE);
        let p = b.upload("params", &[SortParams { n, tiles: groups, pass, passes: 8 }]).unwrap();
        let k = b.upload("keys", keys).unwrap();
        let (ranks, counts, sizes) = (b.zeroed("ranks", n as u64 * 4).unwrap(), b.zeroed("counts", n as u64 * 4).unwrap(), b.zeroed("sizes", groups as u64 * 4).unwrap());
        b.dispatch(Kernel::Multisplit, &[&p, &k, &ranks, &counts, &sizes], groups);
        (b.read(&ranks, n as usize).unwrap(), b.read(&counts, n as usize).unwrap(), b.read(&sizes, groups as usize).unwrap())
    }
    let Some(ctx) = gpu() else { return };
    let seed = treelet_tests::fresh_seed();
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    for (n, distinct) in [(1usize, 256u64), (31, 4), (256, 256), (1000, 3), (70_001, 256), (5000, 1)] {
        // Digits from a few values (long runs of equal ones) to all 256.
        let keys: Vec<u64> = (0..n).map(|_| rng.random::<u64>() & !(0xffu64 << 8) | (rng.random_range(0..distinct) << 8)).collect();
        for pass in [0u32, 1] {
            let (ranks, counts, sizes) = run(&mut GpuBackend::new(ctx.clone()), &keys, pass);
            let size = sizes[0];
            assert!(size.is_power_of_two() && sizes.iter().all(|&s| s == size), "subgroup sizes seen: {:?}", &sizes[..sizes.len().min(8)]);
            if n == 1 && pass == 0 {
                eprintln!("{} runs subgroups of {size} lanes", ctx.info.name);
            }
            let cpu = run(&mut CpuBackend::with_subgroup_size(size), &keys, pass);
            assert!(cpu == (ranks.clone(), counts.clone(), sizes.clone()), "n {n}, pass {pass}, subgroup size {size}: GPU and CPU differ");
            let digit = |i: usize| (keys[i] >> (8 * pass)) & 0xff;
            for i in 0..n {
                let first = i / size as usize * size as usize;
                let last = (first + size as usize).min(n);
                let below = (first..i).filter(|&k| digit(k) == digit(i)).count() as u32;
                let all = (first..last).filter(|&k| digit(k) == digit(i)).count() as u32;
                assert_eq!((ranks[i], counts[i]), (below, all), "n {n}, pass {pass}, key {i}, subgroup size {size}");
            }
        }
    }
}

/// Asked for the pass ranked by subgroups on a device whose subgroups are
/// too small for it, the sort says so instead of sorting wrong.
#[test]
fn sort_ranked_by_subgroups_refuses_small_subgroups() {
    let mut b = CpuBackend::with_subgroup_size(16);
    let keys: Vec<u64> = (0..5000u64).rev().collect();
    let values: Vec<u32> = (0..5000).collect();
    let (kb, vb) = (b.upload("keys", &keys).unwrap(), b.upload("values", &values).unwrap());
    let err = treelet::bvh::sort::radix_sort_tiled(&mut b, &kb, &vb, 5000, 64, SortTiles::Multisplit).err().expect("an error");
    assert!(err.to_string().contains("subgroups of at least 32 lanes"), "{err}");
}
