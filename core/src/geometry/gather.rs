//! An engine's mesh, read where the engine keeps it: positions at any
//! offset and stride in its vertex buffer, triangles as `u16` or `u32`
//! indices (or none: three vertices a triangle), gathered on the device
//! into Treelet's [`Triangle`] buffer, with the first triangle that names a
//! vertex past the end and the first one with a coordinate that is not
//! finite recorded, so the host can name them (nothing read out of
//! bounds, nothing dropped silently).
use crate::geometry::buffers::GatherParams;
use crate::geometry::triangle::Triangle;
use crate::gpu::atomics::min_device;

/// [`GatherParams::index_bytes`] of a mesh without an index buffer.
pub const NO_INDICES: u32 = 0;

/// Vertex `k` of triangle `id`'s index: its index buffer's entry, or
/// `3 id + k` without one.
#[inline]
fn vertex_index(p: &GatherParams, indices: &[u32], id: u32, k: u32) -> u32 {
    let entry = 3 * id + k;
    if p.index_bytes == NO_INDICES {
        entry
    } else if p.index_bytes == 2 {
        // Little-endian halves of 32-bit words.
        let byte = p.index_offset + 2 * entry;
        (indices[(byte / 4) as usize] >> (8 * (byte % 4))) & 0xFFFF
    } else {
        indices[(p.index_offset / 4 + entry) as usize]
    }
}

/// Vertex `index`'s position, and whether `index` is past the end (vertex
/// 0's position is read instead).
#[inline]
fn vertex(p: &GatherParams, vertices: &[u32], index: u32) -> ([f32; 3], bool) {
    let bad = index >= p.vertices;
    let word = ((p.vertex_offset + if bad { 0 } else { index } * p.vertex_stride) / 4) as usize;
    ([f32::from_bits(vertices[word]), f32::from_bits(vertices[word + 1]), f32::from_bits(vertices[word + 2])], bad)
}

/// Kernel: triangle `id < p.triangles` from the engine's buffers into
/// `out[id]`. `vertices` and `indices` are the engine's buffers as words;
/// `flags[0]` and `flags[1]` (`u32::MAX` before) get the least id of a
/// triangle naming a vertex `>= p.vertices` (read as vertex 0 instead) and
/// of one with a non-finite coordinate or an extent past f32's range.
#[inline]
pub fn gather_triangles_kernel(id: u32, p: &GatherParams, vertices: &[u32], indices: &[u32], out: &mut [Triangle], flags: &mut [u32]) {
    if id >= p.triangles {
        return;
    }
    let (v0, bad0) = vertex(p, vertices, vertex_index(p, indices, id, 0));
    let (v1, bad1) = vertex(p, vertices, vertex_index(p, indices, id, 1));
    let (v2, bad2) = vertex(p, vertices, vertex_index(p, indices, id, 2));
    if bad0 || bad1 || bad2 {
        min_device(&mut flags[0], id);
    }
    // Coordinates, and the box's extent (which must not overflow either).
    let finite = |v: [f32; 3]| v[0].is_finite() && v[1].is_finite() && v[2].is_finite();
    let extent = |k: usize| v0[k].max(v1[k]).max(v2[k]) - v0[k].min(v1[k]).min(v2[k]);
    if !(finite(v0) && finite(v1) && finite(v2) && finite([extent(0), extent(1), extent(2)])) {
        min_device(&mut flags[1], id);
    }
    out[id as usize] = Triangle::new(v0, v1, v2);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_strided_vertices_and_u16_indices() {
        // Three vertices of 5 words (a position, then two words of the
        // engine's own), after 2 words.
        let mut vertices = [0u32; 17];
        for (k, p) in [[1.0f32, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]].iter().enumerate() {
            vertices[2 + 5 * k..5 + 5 * k].copy_from_slice(&p.map(f32::to_bits));
            vertices[5 + 5 * k..7 + 5 * k].copy_from_slice(&[0xDEAD, 0xBEEF]);
        }
        // u16 indices 2, 0, 1 and 1, 1, 7 (past the end) after 2 bytes.
        let halves = [0xFFFFu32, 2, 0, 1, 1, 1, 7, 0];
        let indices: [u32; 4] = core::array::from_fn(|k| halves[2 * k] | halves[2 * k + 1] << 16);
        let p = GatherParams { triangles: 2, vertices: 3, vertex_offset: 8, vertex_stride: 20, index_offset: 2, index_bytes: 2, _pad: [0; 2] };
        let mut out = [Triangle::default(); 2];
        let mut flags = [u32::MAX; 2];
        for id in 0..3 {
            gather_triangles_kernel(id, &p, &vertices, &indices, &mut out, &mut flags);
        }
        assert_eq!(out[0], Triangle::new([7.0, 8.0, 9.0], [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]));
        assert_eq!(flags, [1, u32::MAX]);
    }
}
