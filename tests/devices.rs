//! One render on several devices (`treelet::render::devices`): the image is
//! the one-device image (exactly, up to float rounding, when every device
//! is a CPU runner; within the GPU-vs-CPU tolerance with a GPU among them),
//! every sample is rendered once, and a device that fails leaves its
//! unfinished chunk to the others.
use treelet::bvh::layout::Layout;
use treelet::render::devices::{render_on_devices, Device};
use treelet::render::queue::{SampleQueue, Take};
use treelet::render::{Control, InjectedFailure, RenderResult};
use treelet::render::variant::KernelChoice;
use treelet::bvh::tree::Accel;
use treelet::render::{render, Integrator, RenderSettings};
use treelet::runtime::cpu_runner::CpuBackend;
use treelet::runtime::gpu::GpuBackend;
use treelet::scene::{cornell, Scene};
use treelet_tests::{fresh_seed, gpu};

fn settings(spp: u32, seed: u32) -> RenderSettings {
    RenderSettings {
        width: 64,
        height: 48,
        spp,
        seed,
        accel: Accel::Auto,
        layout: Layout::Auto,
        kernel: KernelChoice::Auto,
        integrator: Integrator::Nee,
        sampler: treelet::render::Sampler::Sobol,
        error_each_pass: false,
        first_sample: 0,
    }
}

fn max_abs(a: &[[f32; 3]], b: &[[f32; 3]]) -> f32 {
    a.iter().zip(b).flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs())).fold(0.0, f32::max)
}

fn mean_abs(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let s: f64 = a.iter().zip(b).flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs() as f64)).sum();
    s / (3 * a.len()) as f64
}

/// `render_on_devices` with no reference, no stop, checkpoint or resume.
fn on_devices(devices: &[Device], scene: &Scene, s: &RenderSettings, inject: Option<InjectedFailure>) -> anyhow::Result<RenderResult> {
    render_on_devices(devices, scene, s, None, Control { inject, ..Control::default() }, |_| {})
}

fn one_device(scene: &Scene, s: &RenderSettings) -> Vec<[f32; 3]> {
    render(&mut CpuBackend::new(), scene, s, None, |_| {}).unwrap().image.pixels
}

#[test]
fn the_queue_hands_out_every_sample_once() {
    let q = SampleQueue::new(5..47, 1);
    let mut seen = vec![0u32; 47];
    let mut taken = Vec::new();
    while let Take::Range(r) = q.take(4) {
        taken.push(r);
    }
    // Everything is out: a device asking now waits (a range may come back).
    assert!(matches!(q.take(4), Take::Wait));
    let back = taken.remove(3);
    q.give_back(back.clone());
    match q.take(1) {
        Take::Range(r) => assert_eq!(r, back),
        _ => panic!("a range given back goes out again"),
    }
    taken.push(back);
    for r in &taken {
        q.finished();
        for i in r.clone() {
            seen[i as usize] += 1;
        }
    }
    assert!(matches!(q.take(4), Take::Done));
    assert!(seen[..5].iter().all(|&c| c == 0) && seen[5..].iter().all(|&c| c == 1), "{seen:?}");
}

#[test]
fn cpu_runners_together_make_the_one_device_image() {
    let scene = cornell();
    let s = settings(37, fresh_seed() as u32);
    let RenderResult { image, shares, .. } = on_devices(&[Device::Cpu, Device::Cpu, Device::Cpu], &scene, &s, None).unwrap();
    assert_eq!(shares.iter().map(|s| s.samples).sum::<u32>(), 37);
    let d = max_abs(&image.pixels, &one_device(&scene, &s));
    assert!(d < 1e-4, "three CPU runners against one: {d}");
}

#[test]
fn a_failed_device_leaves_its_chunk_to_the_others() {
    let scene = cornell();
    let s = settings(48, 11);
    // Device 0 fails on its first chunk (both start with a one-sample chunk,
    // and no device may take more than a quarter of what is left).
    let inject = InjectedFailure { device: 0, chunk: 0 };
    let RenderResult { image, shares, .. } = on_devices(&[Device::Cpu, Device::Cpu], &scene, &s, Some(inject)).unwrap();
    assert!(shares[0].failed.as_deref() == Some("injected failure"), "{shares:?}");
    assert_eq!((shares[0].chunks, shares[0].samples), (0, 0));
    assert!(shares[1].chunks >= 2, "{shares:?}");
    assert_eq!(shares.iter().map(|s| s.samples).sum::<u32>(), 48);
    let d = max_abs(&image.pixels, &one_device(&scene, &s));
    assert!(d < 1e-4, "with a failed device, against one device: {d}");
    // When every device fails, the render fails and says why.
    let e = on_devices(&[Device::Cpu], &scene, &s, Some(InjectedFailure { device: 0, chunk: 0 })).err().unwrap();
    assert!(format!("{e:#}").contains("injected failure"), "{e:#}");
}

/// One GPU through `render_on_devices` (a list of one, in chunks) is the
/// plain render on that GPU; with the CPU runner beside it, the image stays
/// the GPU's within the GPU-vs-CPU tolerance, whichever device took what.
#[test]
fn a_gpu_and_the_cpu_runner_make_the_gpu_image() {
    let Some(ctx) = gpu() else { return };
    let scene = cornell();
    let s = settings(64, 3);
    let alone = render(&mut GpuBackend::new(ctx.clone()), &scene, &s, None, |_| {}).unwrap().image.pixels;
    let RenderResult { image: chunked, shares, .. } = on_devices(&[Device::Gpu(ctx.clone())], &scene, &s, None).unwrap();
    assert!(shares[0].chunks >= 2, "{shares:?}");
    let d = max_abs(&chunked.pixels, &alone);
    assert!(d < 1e-4, "the GPU in chunks against the GPU in one render: {d}");
    let RenderResult { image: both, shares, .. } = on_devices(&[Device::Gpu(ctx), Device::Cpu], &scene, &s, None).unwrap();
    assert!(shares.iter().all(|s| s.failed.is_none()), "{shares:?}");
    assert_eq!(shares.iter().map(|s| s.samples).sum::<u32>(), 64);
    let other_seed = render(&mut CpuBackend::new(), &scene, &settings(64, 4), None, |_| {}).unwrap().image.pixels;
    let (diff, noise) = (mean_abs(&both.pixels, &alone), mean_abs(&alone, &other_seed));
    eprintln!("GPU + CPU runner against the GPU alone: mean |diff| {diff:.2e}, noise {noise:.2e}; shares {shares:?}");
    assert!(diff < 0.25 * noise, "GPU + CPU against GPU: {diff}, noise {noise}");
}

/// Sums stay on each device until the end, so a device that fails after
/// some chunks has read none of them back: they all go back to the queue,
/// the other device renders them again, and the image is still the
/// one-device image, with every sample counted once.
#[test]
fn a_device_failing_late_hands_back_its_unread_chunks() {
    let scene = cornell();
    let s = RenderSettings { width: 16, height: 16, ..settings(256, 13) };
    // Device 0 renders its first chunk, then fails as it takes its second
    // (device 1 takes at most a quarter of what is left at a time, so a
    // second chunk is there for it).
    let inject = InjectedFailure { device: 0, chunk: 1 };
    let RenderResult { image, shares, samples, .. } = on_devices(&[Device::Cpu, Device::Cpu], &scene, &s, Some(inject)).unwrap();
    assert_eq!(shares[0].failed.as_deref(), Some("injected failure"), "{shares:?}");
    assert_eq!((shares[0].samples, shares[1].samples), (0, 256), "the failed device's chunk counts for nothing: {shares:?}");
    assert_eq!(samples, 0..256);
    let d = max_abs(&image.pixels, &one_device(&scene, &s));
    assert!(d < 1e-4, "with a late failure, against one device: {d}");
}
