//! The shader build itself: built only with this crate's feature
//! `rebuild-shaders` (rust-gpu, the pinned nightly, several minutes), which
//! `.ci/run` turns on; a plain `cargo test` runs the committed SPIR-V.
//!
//!     cargo test -p treelet-tests --features rebuild-shaders --test shaders

/// The committed SPIR-V modules (what `treelet` builds without feature
/// `rebuild-shaders` load, so that they need no nightly) are the modules
/// rust-gpu compiles from today's `shader/` and `core/`. rust-gpu's output
/// depends on the sources alone (the same bytes from two checkouts at
/// different paths).
#[test]
fn committed_spirv_is_the_shader_sources_build() {
    assert!(treelet::runtime::gpu::SHADERS_REBUILT, "this test needs treelet's feature rebuild-shaders");
    let committed = std::fs::read(treelet::runtime::gpu::COMMITTED_SHADERS_PATH).expect("the committed SPIR-V modules");
    let fresh = treelet::runtime::gpu::SHADERS;
    assert!(
        committed == fresh,
        "{} ({} bytes) is not the build of today's shader sources ({} bytes): run \
         `cargo run -p treelet --features rebuild-shaders --example update_shaders` and commit it",
        treelet::runtime::gpu::COMMITTED_SHADERS_PATH,
        committed.len(),
        fresh.len()
    );
}

/// The shader build fits on a machine of 8 GB (issue 69: one rust-gpu run
/// over every kernel peaked at 22 GB; `host/build.rs` builds them in
/// groups). The figure is the largest process the build ran, measured by
/// the build script when it ran.
#[test]
fn the_shader_build_peaks_under_8_gb() {
    let kb: i64 = treelet::runtime::gpu::SHADER_BUILD_PEAK_RSS_KB
        .expect("the build script records the shader build's peak memory")
        .parse()
        .expect("a number of KiB");
    assert!(kb > 0, "getrusage failed in the build script ({kb})");
    let gb = kb as f64 * 1024.0 / 1e9;
    eprintln!("shader build peak RSS: {gb:.2} GB");
    assert!(gb < 8.0, "the shader build's largest process peaked at {gb:.2} GB, past 8 GB: split its groups further (host/build.rs)");
}
