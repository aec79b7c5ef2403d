//! An engine's frame loop with Treelet inside, on the engine's own wgpu
//! device: the engine opens its device (asking for what Treelet needs),
//! keeps its mesh in its own vertex and index buffers, and each frame moves
//! the mesh, has Treelet rebuild (first frame) or refit its tree from those
//! buffers, traces its camera's rays into a buffer it owns, and shades the
//! hits in a compute pass of its own (WGSL). Nothing is read back between
//! the build and the shading; the last frame's picture is read back and
//! written at the end.
//!
//!     cargo run --release -p treelet --example engine_frames [FRAMES] [OUT.png] [GRID]
//!
//! Runs on the first Vulkan GPU, or lavapipe where there is none.
use std::time::Instant;

use anyhow::{Context, Result};
use treelet::tracer::{device_rays, IndexBuffer, IndexFormat, MeshBuffers};
use treelet::wgpu;
use treelet::{Backend, GpuBackend, GpuContext, Quality, Ray, Tracer};

/// The engine's mesh: a wavy sheet of `grid x grid` quads, 256 unless the
/// third argument says otherwise.
const GRID: u32 = 256;
/// The engine's vertex: position, normal, uv (8 f32: a stride of 32 bytes).
const VERTEX_WORDS: usize = 8;
const WIDTH: u32 = 480;
const HEIGHT: u32 = 270;

/// The sheet at time `t`: vertices (the engine's layout) and indices.
fn sheet(t: f32, grid: u32) -> Vec<f32> {
    let mut v = Vec::with_capacity(((grid + 1) * (grid + 1)) as usize * VERTEX_WORDS);
    for j in 0..=grid {
        for i in 0..=grid {
            let (x, z) = (i as f32 / grid as f32 * 20.0 - 10.0, j as f32 / grid as f32 * 20.0 - 10.0);
            let y = (x * 0.7 + t).sin() * (z * 0.5 - 0.5 * t).cos();
            v.extend([x, y, z, 0.0, 1.0, 0.0, i as f32 / grid as f32, j as f32 / grid as f32]);
        }
    }
    v
}

fn indices(grid: u32) -> Vec<u32> {
    let row = grid + 1;
    (0..grid * grid)
        .flat_map(|q| {
            let (i, j) = (q % grid, q / grid);
            let a = j * row + i;
            [a, a + row, a + 1, a + 1, a + row, a + row + 1]
        })
        .collect()
}

/// The engine's camera: above the sheet, looking down at it.
fn camera_rays() -> Vec<Ray> {
    let eye = glam::Vec3::new(0.0, 9.0, 14.0);
    let forward = (glam::Vec3::ZERO - eye).normalize();
    let right = forward.cross(glam::Vec3::Y).normalize();
    let up = right.cross(forward);
    (0..WIDTH * HEIGHT)
        .map(|p| {
            let (x, y) = ((p % WIDTH) as f32 + 0.5, (p / WIDTH) as f32 + 0.5);
            let (u, v) = ((x / WIDTH as f32 - 0.5) * WIDTH as f32 / HEIGHT as f32, 0.5 - y / HEIGHT as f32);
            Ray::new(eye.into(), (forward + right * u * 0.9 + up * v * 0.9).normalize().into())
        })
        .collect()
}

/// The engine's shading: a hit's normal (the second of its two vec4s:
/// see `Tracer::closest_hits_on_device`) lit by one light, sky where the
/// ray missed, packed into RGBA8.
const SHADE_WGSL: &str = r#"
@group(0) @binding(0) var<storage, read> hits: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> image: array<u32>;

@compute @workgroup_size(64)
fn shade(@builtin(global_invocation_id) id: vec3<u32>) {
    let k = id.x;
    if (k >= arrayLength(&image)) { return; }
    let first = hits[2u * k];
    var c = vec3<f32>(0.55, 0.7, 0.9);
    if (bitcast<u32>(first.y) != 0xFFFFFFFFu) {
        let n = hits[2u * k + 1u].xyz;
        let l = normalize(vec3<f32>(0.4, 1.0, 0.3));
        c = vec3<f32>(0.9, 0.6, 0.3) * (0.15 + 0.85 * abs(dot(n, l)));
    }
    let q = vec3<u32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0);
    image[k] = q.x | (q.y << 8u) | (q.z << 16u) | (255u << 24u);
}
"#;

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let frames: u32 = args.first().map_or(Ok(30), |f| f.parse()).context("FRAMES: a number")?;
    anyhow::ensure!(frames >= 1, "FRAMES: at least 1");
    let out = args.get(1).cloned().unwrap_or_else(|| "engine_frames.png".into());
    let grid: u32 = args.get(2).map_or(Ok(GRID), |g| g.parse()).context("GRID: a number")?;
    anyhow::ensure!((1..=4096).contains(&grid), "GRID {grid}: from 1 to 4096 quads a side");

    // 1. The engine's device, opened with the features and limits Treelet needs.
    treelet::runtime::gpu::quiet_mesa_runtime_dir();
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    desc.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(desc);
    let mut adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
    adapters.sort_by_key(|a| a.get_info().device_type != wgpu::DeviceType::DiscreteGpu);
    let adapter = adapters.into_iter().next().context("no Vulkan adapter (install lavapipe: sh scripts/setup)")?;
    let descriptor = wgpu::DeviceDescriptor {
        label: Some("the engine's device"),
        required_features: GpuContext::required_features(),
        required_limits: GpuContext::required_limits(adapter.limits()),
        // SAFETY: Treelet's kernels are SPIR-V passed through (an
        // experimental wgpu feature), validated by the driver.
        experimental_features: unsafe { wgpu::ExperimentalFeatures::enabled() },
        ..Default::default()
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))?;
    let b = &mut GpuBackend::new(GpuContext::from_wgpu(&adapter, device.clone(), queue.clone())?);
    println!("{}: {} triangles, {WIDTH}x{HEIGHT} rays, {frames} frames", b.adapter(), 2 * grid * grid);

    // 2. The engine's buffers: its mesh, its rays (the hits come back in
    //    place), its image; and its shading pipeline.
    let storage = |label, size: u64| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    };
    let first = sheet(0.0, grid);
    let vertices = storage("engine vertices", first.len() as u64 * 4);
    let index_data = indices(grid);
    let index_buffer = storage("engine indices", index_data.len() as u64 * 4);
    queue.write_buffer(&index_buffer, 0, bytemuck::cast_slice(&index_data));
    let rays = camera_rays();
    let ray_words = device_rays(&rays)?;
    let ray_buffer = storage("engine rays", ray_words.len() as u64 * 16);
    let picture = storage("engine image", (WIDTH * HEIGHT) as u64 * 4);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some("shade"), source: wgpu::ShaderSource::Wgsl(SHADE_WGSL.into()) });
    let shade = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("shade"),
        layout: None,
        module: &module,
        entry_point: Some("shade"),
        compilation_options: Default::default(),
        cache: None,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("shade"),
        layout: &shade.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: ray_buffer.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: picture.as_entire_binding() },
        ],
    });
    let mesh = MeshBuffers::<GpuBackend> {
        vertices: &vertices,
        vertex_offset: 0,
        vertex_stride: (VERTEX_WORDS * 4) as u64,
        vertex_count: (grid + 1) * (grid + 1),
        indices: Some(IndexBuffer { buffer: &index_buffer, offset: 0, format: IndexFormat::U32 }),
        triangle_count: 2 * grid * grid,
    };

    // 3. Frames.
    let mut tracer: Option<Tracer<GpuBackend>> = None;
    let (mut frame_ms, mut update_ms, mut trace_ms) = (Vec::new(), Vec::new(), Vec::new());
    for frame in 0..frames {
        let start = Instant::now();
        queue.write_buffer(&vertices, 0, bytemuck::cast_slice(&sheet(frame as f32 * 0.1, grid)));
        match &mut tracer {
            None => tracer = Some(Tracer::build_from_buffers(b, &mesh, Quality::Fast)?),
            Some(t) => t.refit_from_buffers(b, &mesh)?,
        }
        queue.write_buffer(&ray_buffer, 0, bytemuck::cast_slice(&ray_words));
        let t = tracer.as_ref().expect("built on the first frame");
        update_ms.push(t.last_update_ms());
        t.closest_hits_on_device(b, &ray_buffer, rays.len())?;
        // Treelet's recorded work goes to the shared queue before the
        // engine's pass that reads the hits.
        b.submit()?;
        // The trace's device time (the update's is the tracer's own).
        trace_ms.push(b.take_times()?.total());
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&shade);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((WIDTH * HEIGHT).div_ceil(64), 1, 1);
        }
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        frame_ms.push(start.elapsed().as_secs_f64() * 1e3);
    }
    let median = |v: &[f64]| {
        let mut later = v[1..].to_vec();
        later.sort_by(f64::total_cmp);
        later.get(later.len() / 2).map_or("-".to_string(), |m| format!("{m:.3} ms"))
    };
    println!("frame 0 (gather, build, trace, shade): {:.2} ms wall, tree build {:.3} ms device, trace {:.3} ms device", frame_ms[0], update_ms[0], trace_ms[0]);
    println!(
        "later frames (write the mesh, gather, refit, trace, shade), median: {} wall, refit {} device, trace {} device",
        median(&frame_ms),
        median(&update_ms),
        median(&trace_ms)
    );

    // 4. The last picture, read back once.
    let pixels: Vec<u32> = b.read(&picture, (WIDTH * HEIGHT) as usize)?;
    let bytes: Vec<u8> = bytemuck::cast_slice(&pixels).to_vec();
    image::RgbaImage::from_raw(WIDTH, HEIGHT, bytes).context("image size")?.save(&out)?;
    println!("wrote {out}");
    Ok(())
}
