//! An engine's mesh where the engine keeps it: positions in its vertex
//! buffer (any offset and stride), triangles as `u16` or `u32` indices in
//! its index buffer, or three vertices a triangle without one. Gathered
//! on the device into the triangles a tree is built over and traced
//! against (`Kernel::GatherTriangles`, `treelet_core::geometry::gather`),
//! with no copy through the host; what the engine's buffers say is checked
//! first (sizes, alignment), and what they hold by the gather (indices
//! past the vertices, coordinates that are not finite), the first bad
//! triangle named.
use anyhow::Result;
use treelet_core::geometry::buffers::{GatherParams, Sphere};
use treelet_core::gpu::workgroup::{groups_for, WORKGROUP_SIZE};

use crate::bvh::layout::PrimBuffers;
use crate::runtime::backend::Backend;
use crate::runtime::kernel_set::kernel_set;
use crate::runtime::kernels::{bind, Kernel};

kernel_set! {
    /// The kernel gathering an engine's mesh into triangles.
    pub struct GatherKernels for b {
        gather: Kernel::GatherTriangles,
    }
}
use crate::scene::primitives::MAX_PRIMITIVES;

/// The integer type of an index buffer's entries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndexFormat {
    U16,
    U32,
}

impl IndexFormat {
    fn bytes(self) -> u64 {
        match self {
            IndexFormat::U16 => 2,
            IndexFormat::U32 => 4,
        }
    }
}

/// An engine's index buffer: three entries a triangle from `offset` (bytes,
/// a multiple of the entry's size).
pub struct IndexBuffer<'a, B: Backend> {
    pub buffer: &'a B::Buffer,
    pub offset: u64,
    pub format: IndexFormat,
}

/// An engine's mesh in its own buffers (on a GPU, `wgpu::Buffer`s made
/// with `BufferUsages::STORAGE` on the device the tracer's backend uses):
/// vertex `k`'s position is three f32 at byte `vertex_offset + k *
/// vertex_stride` of `vertices` (both multiples of 4; the stride at least
/// 12), triangle `t` is vertices `indices[3t..3t + 3]`, or `3t..3t + 3`
/// without an index buffer.
pub struct MeshBuffers<'a, B: Backend> {
    pub vertices: &'a B::Buffer,
    pub vertex_offset: u64,
    pub vertex_stride: u64,
    pub vertex_count: u32,
    pub indices: Option<IndexBuffer<'a, B>>,
    pub triangle_count: u32,
}

impl<B: Backend> MeshBuffers<'_, B> {
    /// Checks what the mesh says against its buffers; the gather's
    /// parameters (the index offset made relative to `index_base` bytes, where
    /// the index words are bound from).
    fn params(&self, b: &B, index_base: u64) -> Result<GatherParams> {
        let (n, v) = (self.triangle_count as u64, self.vertex_count as u64);
        if !(n <= MAX_PRIMITIVES as u64) {
 return Err(crate::error::too_large(format!("engine mesh: {n} triangles: at most {MAX_PRIMITIVES} are supported")));
 }
        if !(self.vertex_stride >= 12 && self.vertex_stride % 4 == 0 && self.vertex_offset % 4 == 0) {
 return Err(crate::error::input(format!("engine mesh: vertex stride {} and offset {} (bytes) must be multiples of 4, the stride at least 12 (three f32)",
            self.vertex_stride,
            self.vertex_offset)));
 }
        let vertex_bytes = b.buffer_bytes(self.vertices);
        let vertex_end = if v == 0 { 0 } else { self.vertex_offset + (v - 1) * self.vertex_stride + 12 };
        if !(vertex_end <= vertex_bytes) {
 return Err(crate::error::input(format!("engine mesh: {v} vertices of stride {} from byte {} reach byte {vertex_end}, past the vertex buffer's {vertex_bytes} bytes",
            self.vertex_stride,
            self.vertex_offset)));
 }
        if !(vertex_end <= u32::MAX as u64) {
 return Err(crate::error::too_large(format!("engine mesh: the vertices reach byte {vertex_end}: at most 4 GiB are read")));
 }
        fits_binding(b, "vertex buffer", vertex_bytes)?;
        fits_binding(b, "triangles gathered", n * 48)?;
        let (index_offset, index_bytes) = match &self.indices {
            None => {
                if !(v >= 3 * n) {
 return Err(crate::error::input(format!("engine mesh: {n} triangles without an index buffer need {} vertices, not {v}", 3 * n)));
 }
                (0, treelet_core::geometry::gather::NO_INDICES)
            }
            Some(i) => {
                let size = i.format.bytes();
                if !(i.offset % size == 0) {
 return Err(crate::error::input(format!("engine mesh: index offset {} is not a multiple of the {size}-byte entries", i.offset)));
 }
                let end = i.offset + 3 * n * size;
                let bytes = b.buffer_bytes(i.buffer);
                if !(end <= bytes) {
 return Err(crate::error::input(format!("engine mesh: {n} triangles of {size}-byte indices from byte {} reach byte {end}, past the index buffer's {bytes} bytes", i.offset)));
 }
                fits_binding(b, "index buffer", bytes)?;
                ((i.offset - index_base) as u32, size as u32)
            }
        };
        Ok(GatherParams {
            triangles: self.triangle_count,
            vertices: self.vertex_count,
            vertex_offset: self.vertex_offset as u32,
            vertex_stride: self.vertex_stride as u32,
            index_offset,
            index_bytes,
            _pad: [0; 2],
        })
    }
}

/// The mesh's triangles gathered into a buffer of Treelet's on `b` (taken
/// from its pool: call after `b.begin_build()`), checked: an error names
/// the first triangle with an index past the vertices, or with a
/// coordinate that is not finite (one read back of two words, which waits
/// for the gather).
pub(super) fn gather<B: Backend>(b: &mut B, mesh: &MeshBuffers<B>, into: Option<&PrimBuffers<B>>) -> Result<PrimBuffers<B>> {
    let n = mesh.triangle_count;
    let (spheres, triangles) = match into {
        // The same count: the last gather's buffers, written over in queue order.
        Some(p) if p.triangle_count == n && p.sphere_count == 0 => (p.spheres.clone(), p.triangles.clone()),
        _ => (b.upload("no spheres", &[Sphere::default()])?, b.scratch("engine triangles", (n as u64).max(1) * 48)?),
    };
    if n == 0 {
        return Ok(PrimBuffers { spheres, triangles, sphere_count: 0, triangle_count: 0 });
    }
    b.stage("gather");
    // Bound once each: an index buffer that is the vertex buffer has its
    // index words copied out first (a kernel binds a buffer once).
    let (indices, index_base) = match &mesh.indices {
        None => (b.upload("no indices", &[0u32])?, 0),
        Some(i) if b.same_buffer(i.buffer, mesh.vertices) => {
            let first = i.offset / 4;
            let words = (i.offset + 3 * n as u64 * i.format.bytes()).div_ceil(4) - first;
            let own = b.scratch("engine indices", words * 4)?;
            b.copy_words((i.buffer, first as u32), (&own, 0), words as u32)?;
            (own, first * 4)
        }
        Some(i) => (i.buffer.clone(), 0),
    };
    let p = b.upload("gather params", &[mesh.params(b, index_base)?])?;
    let flags = b.upload("gather flags", &[u32::MAX; 2])?;
    let gather = bind::GatherTriangles { params: &p, vertices: mesh.vertices, indices: &indices, out: &triangles, flags: &flags };
    b.dispatch_with(GatherKernels::of(b).gather, gather, groups_for(n, WORKGROUP_SIZE));
    let flags = b.read::<u32>(&flags, 2)?;
    if flags[0] != u32::MAX {
        return Err(crate::error::input(format!("engine mesh: triangle {} names a vertex past the {} vertices", flags[0], mesh.vertex_count)));
    }
    if flags[1] != u32::MAX {
        return Err(crate::error::input(format!("engine mesh: triangle {} has a coordinate that is not finite (or an extent past f32's range)", flags[1])));
    }
    Ok(PrimBuffers { spheres, triangles, sphere_count: 0, triangle_count: n })
}

/// The gather binds each buffer whole.
fn fits_binding<B: Backend>(b: &B, what: &str, bytes: u64) -> Result<()> {
    let max = b.max_binding_bytes();
    if !(bytes <= max) {
 return Err(crate::error::too_large(format!("engine mesh: the {what} ({bytes} bytes) is larger than one binding of `{}` holds ({max} bytes)", b.adapter())));
 }
    Ok(())
}
