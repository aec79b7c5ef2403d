//! The common OBJ, read on every core: `v x y z` and `f` lines (indices as
//! `i`, `i/t`, `i//n` or `i/t/n`, counted from 1 or, when negative, back
//! from the last vertex so far) among the lines a mesh does not need
//! (comments, `vt`, `vn`, `o`, `g`, `s`, `usemtl`, `mtllib`). Scanned and
//! exported meshes come so, and tobj reads them line by line on one core.
//! The file is cut into chunks at line ends; each chunk is parsed apart,
//! and its relative indices are settled once the vertices before it are
//! counted. Every other OBJ, and any file this reader finds a doubt in (a
//! bad number, an index out of range, a face of fewer than three vertices,
//! another keyword), goes to tobj ([`super::mesh::load_obj`]), so that its
//! errors are tobj's, with the line that [`super::mesh`] finds for them.
use anyhow::Result;
use rayon::prelude::*;
use treelet_core::geometry::triangle::Triangle;

use crate::internals::input::room_for;

/// Bytes a chunk takes at least: enough to keep a core busy for a while,
/// few enough to share a file of a few megabytes among the cores.
const CHUNK_BYTES: usize = 1 << 20;

/// One chunk's vertices and faces. A face is its vertex count in `sizes`
/// and its indices in `indices`: 0-based, from the start of the file
/// (`Absolute`), or from this chunk's first vertex (`Local`, which may be
/// negative: a vertex of an earlier chunk).
#[derive(Default)]
struct Chunk {
    vertices: Vec<[f32; 3]>,
    sizes: Vec<u32>,
    indices: Vec<Index>,
}

#[derive(Clone, Copy)]
enum Index {
    Absolute(i64),
    Local(i64),
}

/// The triangles of `text`, faces fanned from their first vertex as tobj
/// triangulates them, in the file's order; `None` where tobj should read
/// the file instead (see the module doc); an error where the memory cannot
/// hold the triangles.
pub(super) fn read(text: &str, name: &str) -> Option<Result<Vec<Triangle>>> {
    read_in_chunks(text, name, CHUNK_BYTES)
}

/// [`read`] in chunks of `chunk_bytes` or more (tests cut small files small).
pub(super) fn read_in_chunks(text: &str, name: &str, chunk_bytes: usize) -> Option<Result<Vec<Triangle>>> {
    let bytes = text.as_bytes();
    let progress = crate::internals::progress::track(format!("parsing {name}"), bytes.len() as u64);
    let chunks: Vec<Chunk> = chunk_ranges(bytes, chunk_bytes)
        .into_par_iter()
        .map(|r| {
            let chunk = parse_chunk(&bytes[r.clone()]);
            progress.add(r.len() as u64);
            chunk
        })
        .collect::<Option<_>>()?;
    drop(progress);
    // Where each chunk's vertices start in the file, and where its triangles go.
    let mut vertex_base = Vec::with_capacity(chunks.len());
    let mut triangle_base = Vec::with_capacity(chunks.len());
    let (mut vertices, mut triangles) = (0i64, 0usize);
    for c in &chunks {
        vertex_base.push(vertices);
        triangle_base.push(triangles);
        vertices += c.vertices.len() as i64;
        triangles += c.sizes.iter().map(|&s| s as usize - 2).sum::<usize>();
    }
    let mut all = match room_for(vertices as usize, "the mesh's vertices") {
        Ok(v) => v,
        Err(e) => return Some(Err(e)),
    };
    all.extend(chunks.iter().flat_map(|c| c.vertices.iter().copied()));
    let mut out = match room_for(triangles, "the mesh's triangles") {
        Ok(v) => v,
        Err(e) => return Some(Err(e)),
    };
    out.resize(triangles, Triangle::default());
    // Each chunk fills its own run of `out`.
    let mut runs = Vec::with_capacity(chunks.len());
    let mut rest = out.as_mut_slice();
    for (i, c) in chunks.iter().enumerate() {
        let end = triangle_base.get(i + 1).copied().unwrap_or(triangles) - triangle_base[i];
        let (run, tail) = rest.split_at_mut(end);
        runs.push((c, vertex_base[i], run));
        rest = tail;
    }
    runs.into_par_iter()
        .map(|(c, base, run)| {
            let vertex = |index: Index| -> Option<[f32; 3]> {
                let i = match index {
                    Index::Absolute(i) => i,
                    Index::Local(i) => base + i,
                };
                all.get(usize::try_from(i).ok()?).copied()
            };
            let (mut at, mut t) = (0usize, 0usize);
            for &size in &c.sizes {
                let face = &c.indices[at..at + size as usize];
                let first = vertex(face[0])?;
                for k in 1..face.len() - 1 {
                    run[t] = Triangle::new(first, vertex(face[k])?, vertex(face[k + 1])?);
                    t += 1;
                }
                at += size as usize;
            }
            Some(())
        })
        .collect::<Option<Vec<()>>>()?;
    Some(Ok(out))
}

/// `bytes` cut into ranges of `least` bytes or more (four a core), each
/// ending after a newline (the last at the end).
fn chunk_ranges(bytes: &[u8], least: usize) -> Vec<std::ops::Range<usize>> {
    let size = least.max(1).max(bytes.len() / (4 * rayon::current_num_threads()).max(1));
    let mut ranges = Vec::new();
    let mut start = 0;
    while start < bytes.len() {
        let end = match bytes.get(start + size..).and_then(|rest| rest.iter().position(|&b| b == b'\n')) {
            Some(newline) => start + size + newline + 1,
            None => bytes.len(),
        };
        ranges.push(start..end);
        start = end;
    }
    ranges
}

/// One chunk of whole lines, or `None` at the first doubt.
fn parse_chunk(bytes: &[u8]) -> Option<Chunk> {
    let text = std::str::from_utf8(bytes).ok()?;
    let mut c = Chunk::default();
    for line in text.split('\n') {
        let line = line.strip_suffix('\r').unwrap_or(line);
        if line.ends_with('\\') {
            return None; // a continued line: tobj's
        }
        let mut words = line.split_ascii_whitespace();
        match words.next() {
            None => {}
            Some("v") => {
                let mut p = [0f32; 3];
                for x in &mut p {
                    *x = words.next()?.parse().ok()?;
                }
                if words.next().is_some() {
                    return None; // weights or colours: tobj's
                }
                c.vertices.push(p);
            }
            Some("f") => {
                let before = c.indices.len();
                for word in words {
                    let i: i64 = word.split('/').next()?.parse().ok()?;
                    c.indices.push(match i {
                        0 => return None,
                        i if i > 0 => Index::Absolute(i - 1),
                        i => Index::Local(c.vertices.len() as i64 + i),
                    });
                }
                let size = c.indices.len() - before;
                if size < 3 {
                    return None;
                }
                c.sizes.push(u32::try_from(size).ok()?);
            }
            Some(w) if w.starts_with('#') => {}
            Some("vt" | "vn" | "o" | "g" | "s" | "usemtl" | "mtllib") => {}
            Some(_) => return None,
        }
    }
    Some(c)
}
