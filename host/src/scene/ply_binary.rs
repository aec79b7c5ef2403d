//! The common binary PLY, read at the memory's pace: little-endian, a
//! `vertex` element of scalar properties with `float` `x`, `y`, `z`, then a
//! `face` element whose one property is the list of vertex indices. Scans
//! and large meshes come so (a 53M-triangle, 1 GB file took 37 s through
//! the general parser, which makes a record per element); every other PLY
//! goes to the general parser ([`super::mesh::load_ply`]), and so do files
//! this reader finds any doubt in, so that their errors are that parser's.
//! A file of triangles alone is read in blocks through one buffer
//! ([`load_in_blocks`]), never held whole; the others from the bytes of
//! the whole file ([`read`]). Not memory-mapped: a file cut short by
//! another process while mapped kills the reader (SIGBUS), where a read
//! in blocks gets an error that names the file.
use std::path::Path;

use anyhow::{anyhow, bail, Context as _, Result};
use rayon::prelude::*;
use treelet_core::geometry::triangle::Triangle;

use crate::internals::input;

/// Size in bytes of a PLY scalar type, and whether it is an integer.
fn scalar(name: &str) -> Option<(usize, bool)> {
    Some(match name {
        "char" | "int8" | "uchar" | "uint8" => (1, true),
        "short" | "int16" | "ushort" | "uint16" => (2, true),
        "int" | "int32" | "uint" | "uint32" => (4, true),
        "float" | "float32" => (4, false),
        "double" | "float64" => (8, false),
        _ => return None,
    })
}

/// Reads unsigned little-endian integers of `size` bytes (and signed ones,
/// for the signed type names) at `at`.
#[derive(Clone, Copy)]
struct Int {
    size: usize,
    signed: bool,
}

impl Int {
    fn of(name: &str) -> Option<Int> {
        let (size, integer) = scalar(name)?;
        integer.then(|| Int { size, signed: matches!(name, "char" | "int8" | "short" | "int16" | "int" | "int32") })
    }

    #[inline(always)]
    fn read(self, b: &[u8], at: usize) -> i64 {
        match (self.size, self.signed) {
            (1, false) => b[at] as i64,
            (1, true) => b[at] as i8 as i64,
            (2, false) => u16::from_le_bytes([b[at], b[at + 1]]) as i64,
            (2, true) => i16::from_le_bytes([b[at], b[at + 1]]) as i64,
            (_, false) => u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]) as i64,
            (_, true) => i32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]) as i64,
        }
    }
}

/// What the header says, when it is the layout this reader takes.
struct Layout {
    body: usize,
    vertices: usize,
    stride: usize,
    /// Byte offsets of x, y, z within a vertex.
    xyz: [usize; 3],
    faces: usize,
    count: Int,
    index: Int,
}

fn layout(bytes: &[u8]) -> Option<Layout> {
    let end = bytes.windows(11).take(1 << 16).position(|w| w == b"end_header\n")?;
    let header = std::str::from_utf8(&bytes[..end]).ok()?;
    let mut lines = header.lines().map(str::trim);
    if lines.next()? != "ply" || lines.next()? != "format binary_little_endian 1.0" {
        return None;
    }
    let (mut vertex, mut face) = (None::<(usize, usize, [Option<usize>; 3])>, None::<(usize, Option<(Int, Int)>)>);
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["element", "vertex", n] if vertex.is_none() && face.is_none() => vertex = Some((n.parse().ok()?, 0, [None; 3])),
            ["element", "face", n] if vertex.is_some() && face.is_none() => face = Some((n.parse().ok()?, None)),
            ["property", "list", c, i, "vertex_indices" | "vertex_index"] if face.is_some_and(|f| f.1.is_none()) => {
                face.as_mut()?.1 = Some((Int::of(c)?, Int::of(i)?));
            }
            ["property", t, name] if face.is_none() => {
                let (size, integer) = scalar(t)?;
                let v = vertex.as_mut()?;
                if let Some(axis) = ["x", "y", "z"].iter().position(|a| a == name) {
                    // Only float coordinates, each named once.
                    if integer || size != 4 || v.2[axis].is_some() {
                        return None;
                    }
                    v.2[axis] = Some(v.1);
                }
                v.1 += size;
            }
            _ => return None,
        }
    }
    let (vertices, stride, [Some(x), Some(y), Some(z)]) = vertex? else { return None };
    let (faces, Some((count, index))) = face? else { return None };
    Some(Layout { body: end + 11, vertices, stride, xyz: [x, y, z], faces, count, index })
}

/// The triangles of `bytes` if they are the common binary layout (see the
/// module doc), `None` for any other PLY; errors name the element at fault
/// as the general reader does.
pub fn read(bytes: &[u8], name: &str) -> Option<Result<Vec<Triangle>>> {
    let l = layout(bytes)?;
    Some(triangles(bytes, name, &l))
}

/// The faces when every one is a triangle whose indices are in range, the
/// common case, on every core: then each face is a record of one size, so
/// face `f` starts at `f` times it. `None` where any face is not so (the
/// loop after it then reads the faces one by one and names the fault).
/// Vertices are read from the file's bytes where they lie (`position`),
/// not copied first: at 10M triangles that copy was 360 MB of fresh pages.
fn all_triangles(faces: &[u8], l: &Layout, position: impl Fn(usize) -> [f32; 3] + Sync) -> Option<Result<Vec<Triangle>>> {
    let record = l.count.size + 3 * l.index.size;
    if l.faces.checked_mul(record) != Some(faces.len()) {
        return None;
    }
    let index = |at: usize| usize::try_from(l.index.read(faces, at)).ok().filter(|&i| i < l.vertices);
    let corners = |f: usize| (f * record + l.count.size, l.index.size);
    let fits = (0..l.faces).into_par_iter().all(|f| {
        let (at, step) = corners(f);
        l.count.read(faces, at - l.count.size) == 3 && (0..3).all(|k| index(at + k * step).is_some())
    });
    if !fits {
        return None;
    }
    // Written in place on every core (a collect through rayon's lists of
    // vectors would copy them).
    let mut triangles = match crate::internals::input::room_to_fill(l.faces, "the mesh's triangles") {
        Ok(v) => v,
        Err(e) => return Some(Err(e)),
    };
    (0..l.faces)
        .into_par_iter()
        .map(|f| {
            let (at, step) = corners(f);
            let vertex = |k: usize| position(index(at + k * step).unwrap_or(0));
            Triangle::new(vertex(0), vertex(1), vertex(2))
        })
        .collect_into_vec(&mut triangles);
    Some(Ok(triangles))
}

/// The triangles of the binary PLY at `path`, when it is the common layout
/// and every face a triangle of indices in range, read in blocks through
/// one buffer: the file's bytes are never held whole (at 10M triangles that
/// copy was 490 MB of fresh pages, more than half of the load). `None` for
/// any other file, or where a block finds any doubt: the caller then reads
/// the file whole, and the general path names the fault.
pub fn load_in_blocks(path: &Path, name: &str) -> Result<Option<Vec<Triangle>>> {
    load_in_blocks_of(path, name, BLOCK_BYTES)
}

/// [`load_in_blocks`], `block_bytes` at a time (or one record, if larger).
pub(super) fn load_in_blocks_of(path: &Path, name: &str, block_bytes: usize) -> Result<Option<Vec<Triangle>>> {
    use std::io::Read;
    if input::is_xz(path) {
        return Ok(None);
    }
    let (file, len) = input::open(path, "mesh")?;
    let mut file = file.take(len);
    // The header: `layout` looks for its end within the first 64 KiB.
    let mut head = Vec::new();
    (&mut file).take((1 << 16) + 11).read_to_end(&mut head).with_context(|| format!("{name}: read error"))?;
    let Some(l) = layout(&head) else { return Ok(None) };
    let record = l.count.size + 3 * l.index.size;
    let (Some(vertex_bytes), Some(face_bytes)) = (l.vertices.checked_mul(l.stride), l.faces.checked_mul(record)) else { return Ok(None) };
    if (l.body as u64).checked_add(vertex_bytes as u64).and_then(|b| b.checked_add(face_bytes as u64)) != Some(len) {
        return Ok(None);
    }
    let progress = crate::internals::progress::track(format!("reading mesh {}", path.display()), len);
    let mut blocks = Blocks { file, buffer: Vec::new(), carried: head[l.body..].to_vec(), name };
    // Vertices: their positions alone are kept. Three floats and nothing
    // else, the common case, are read straight into them (no conversion).
    let mut positions: Vec<[f32; 3]> = input::room_to_fill(l.vertices, "the mesh's vertices")?;
    if l.stride == 12 && l.xyz == [0, 4, 8] && cfg!(target_endian = "little") {
        positions.resize(l.vertices, [0.0; 3]);
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut positions);
        for chunk in bytes.chunks_mut(block_bytes.max(1)) {
            blocks.read_into(chunk)?;
            progress.add(chunk.len() as u64);
        }
    } else {
        let f32_at = |b: &[u8], at: usize| f32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
        let mut left = l.vertices;
        while left > 0 {
            let n = left.min(block_bytes / l.stride).max(1);
            let block = blocks.next(n * l.stride)?;
            positions.par_extend(block.par_chunks_exact(l.stride).map(|v| [f32_at(v, l.xyz[0]), f32_at(v, l.xyz[1]), f32_at(v, l.xyz[2])]));
            progress.add((n * l.stride) as u64);
            left -= n;
        }
    }
    // Faces: made into triangles in one pass, which marks any face that is
    // not a triangle of indices in range (the file then goes to the
    // whole-file path, which names it).
    let mut triangles: Vec<Triangle> = input::room_to_fill(l.faces, "the mesh's triangles")?;
    let index = |b: &[u8], at: usize| usize::try_from(l.index.read(b, at)).ok().filter(|&i| i < l.vertices);
    let doubt = std::sync::atomic::AtomicBool::new(false);
    let mut left = l.faces;
    while left > 0 {
        let n = left.min(block_bytes / record).max(1);
        let block = blocks.next(n * record)?;
        triangles.par_extend(block.par_chunks_exact(record).map(|f| {
            let corner = |k: usize| index(f, l.count.size + k * l.index.size);
            match (l.count.read(f, 0), corner(0), corner(1), corner(2)) {
                (3, Some(a), Some(b), Some(c)) => Triangle::new(positions[a], positions[b], positions[c]),
                _ => {
                    doubt.store(true, std::sync::atomic::Ordering::Relaxed);
                    Triangle::default()
                }
            }
        }));
        if doubt.load(std::sync::atomic::Ordering::Relaxed) {
            return Ok(None);
        }
        progress.add((n * record) as u64);
        left -= n;
    }
    blocks.at_end()?;
    Ok(Some(triangles))
}

/// Bytes read at a time by [`load_in_blocks`]: large enough that a block's
/// work spreads over every core, small enough to stay in the caches.
const BLOCK_BYTES: usize = 4 << 20;

/// A file read in blocks of whole records through one buffer, after the
/// bytes already read with the header (`carried`).
struct Blocks<'a> {
    file: std::io::Take<std::fs::File>,
    buffer: Vec<u8>,
    carried: Vec<u8>,
    name: &'a str,
}

impl Blocks<'_> {
    /// The next `n` bytes.
    fn next(&mut self, n: usize) -> Result<&[u8]> {
        let mut buffer = std::mem::take(&mut self.buffer);
        buffer.resize(n, 0);
        let read = self.read_into(&mut buffer);
        self.buffer = buffer;
        read.map(|()| self.buffer.as_slice())
    }

    /// Fills `out` with the next bytes.
    fn read_into(&mut self, out: &mut [u8]) -> Result<()> {
        use std::io::Read;
        let from_carried = out.len().min(self.carried.len());
        out[..from_carried].copy_from_slice(&self.carried[..from_carried]);
        self.carried.drain(..from_carried);
        self.file.read_exact(&mut out[from_carried..]).with_context(|| format!("{}: the file ended early (truncated while read?)", self.name))
    }

    /// Checks that nothing is left: the file did not grow while read.
    fn at_end(self) -> Result<()> {
        use std::io::Read;
        let mut rest = self.file.into_inner();
        if !self.carried.is_empty() || rest.read(&mut [0u8; 1]).with_context(|| format!("{}: read error", self.name))? != 0 {
            bail!("{}: the file grew while it was read", self.name);
        }
        Ok(())
    }
}

fn triangles(bytes: &[u8], name: &str, l: &Layout) -> Result<Vec<Triangle>> {
    let body = &bytes[l.body..];
    let vertex_bytes = l.vertices.checked_mul(l.stride).filter(|&b| b <= body.len());
    let Some(vertex_bytes) = vertex_bytes else {
        bail!("{name}: the header's {} vertices of {} bytes are past the file's end (truncated?)", l.vertices, l.stride);
    };
    let f32_at = |at: usize| f32::from_le_bytes([body[at], body[at + 1], body[at + 2], body[at + 3]]);
    let position = |v: usize| {
        let base = v * l.stride;
        [f32_at(base + l.xyz[0]), f32_at(base + l.xyz[1]), f32_at(base + l.xyz[2])]
    };
    let faces = &body[vertex_bytes..];
    if let Some(triangles) = all_triangles(faces, l, position) {
        return triangles;
    }
    let mut positions = crate::internals::input::room_for(l.vertices, "the mesh's vertices")?;
    (0..l.vertices).into_par_iter().map(position).collect_into_vec(&mut positions);
    // No more room than the file can hold: a face takes at least its count
    // and three indices.
    let smallest = l.count.size + 3 * l.index.size;
    let mut triangles = crate::internals::input::room_for(l.faces.min(faces.len() / smallest), "the mesh's triangles")?;
    let mut at = 0usize;
    for f in 0..l.faces {
        if at + l.count.size > faces.len() {
            bail!("{name}: face {f}: the file ends inside it (truncated?)");
        }
        let n = l.count.read(faces, at);
        at += l.count.size;
        if n < 3 {
            bail!("{name}: face {f} has {n} vertices (at least 3 needed)");
        }
        let n = n as usize;
        if n.checked_mul(l.index.size).is_none_or(|b| at + b > faces.len()) {
            bail!("{name}: face {f}: the file ends inside it (truncated?)");
        }
        let vertex = |k: usize| -> Result<[f32; 3]> {
            let i = l.index.read(faces, at + k * l.index.size);
            usize::try_from(i)
                .ok()
                .and_then(|i| positions.get(i).copied())
                .ok_or_else(|| anyhow!("{name}: face {f}: vertex index {i} out of range 0..{}", positions.len()))
        };
        // A polygon becomes a fan of triangles around its first vertex.
        let first = vertex(0)?;
        for k in 1..n - 1 {
            triangles.push(Triangle::new(first, vertex(k)?, vertex(k + 1)?));
        }
        at += n * l.index.size;
    }
    if at != faces.len() {
        bail!("{name}: {} bytes after the last face: not the layout the header gives", faces.len() - at);
    }
    Ok(triangles)
}
