//! Files a user names (scenes, meshes, images, parts), read safely: only
//! regular files, so that a FIFO cannot block a run and a link to an endless
//! device cannot fill the memory, and none larger than a cap that
//! `--max-input-bytes` raises.
use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{bail, Context as _, Result};

/// The cap on an input file's size unless raised: 8 GiB, above the largest
/// mesh measured (a 14 M triangle PLY of about 300 MB) by far, below what
/// a machine without that much memory could read.
pub const DEFAULT_MAX_INPUT_BYTES: u64 = 8 << 30;

static MAX_INPUT_BYTES: AtomicU64 = AtomicU64::new(DEFAULT_MAX_INPUT_BYTES);

/// Sets the cap on an input file's size (`--max-input-bytes`).
pub fn set_max_input_bytes(bytes: u64) {
    MAX_INPUT_BYTES.store(bytes, Ordering::Relaxed);
}

/// The cap on an input file's size.
pub fn max_input_bytes() -> u64 {
    MAX_INPUT_BYTES.load(Ordering::Relaxed)
}

/// Checks that `path` (a `what`: "scene file", "mesh", ...) is a regular
/// file within the cap, without opening it (opening a FIFO blocks).
/// Returns its size.
pub fn check(path: &Path, what: &str) -> Result<u64> {
    let meta = std::fs::metadata(path).with_context(|| format!("{what} {}: cannot read it", path.display()))?;
    let len = check_meta(path, what, &meta)?;
    note_read(path);
    Ok(len)
}

/// Every file [`check`] passed in this process (so every file read through
/// this module), by its canonical path: the command writes no output over
/// one of them ([`refuse_if_read`]).
static READ: std::sync::Mutex<Vec<std::path::PathBuf>> = std::sync::Mutex::new(Vec::new());

fn note_read(path: &Path) {
    if let Ok(canonical) = path.canonicalize() {
        let mut read = READ.lock().unwrap_or_else(|e| e.into_inner());
        if !read.contains(&canonical) {
            read.push(canonical);
        }
    }
}

/// Takes `path` off the files read (a file read only to be judged, such as
/// a finished part a render will write over again).
pub fn forget_read(path: &Path) {
    if let Ok(canonical) = path.canonicalize() {
        READ.lock().unwrap_or_else(|e| e.into_inner()).retain(|p| *p != canonical);
    }
}

/// Refuses `path` as an output (`what`: `--out`) where this process has read
/// it as an input, by any name that resolves to it: the scene, a mesh or
/// buffer it names, a reference image. (A render's `--report` over its scene
/// file, or `export` over the mesh it exports, replaced the input.)
pub fn refuse_if_read(path: &Path, what: &str) -> Result<()> {
    let Ok(canonical) = path.canonicalize() else { return Ok(()) };
    if READ.lock().unwrap_or_else(|e| e.into_inner()).contains(&canonical) {
        bail!("{what} {}: this command read that file as an input, and writing would replace it; write elsewhere", path.display());
    }
    Ok(())
}

fn check_meta(path: &Path, what: &str, meta: &std::fs::Metadata) -> Result<u64> {
    if meta.is_dir() {
        bail!("{what} {} is a folder, not a file", path.display());
    }
    if !meta.is_file() {
        bail!("{what} {} is not a regular file (a FIFO, socket or device?): only files are read", path.display());
    }
    let max = max_input_bytes();
    if meta.len() > max {
        bail!(
            "{what} {} has {} bytes, more than the {max} bytes an input may have (--max-input-bytes raises it)",
            path.display(),
            meta.len()
        );
    }
    Ok(meta.len())
}

/// An empty vector with room for `n` elements, or an error naming `what`
/// and the bytes asked for where the memory cannot hold them (an
/// allocation that fails would abort the process).
pub fn room_for<T>(n: usize, what: &str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| no_memory::<T>(n, what))?;
    Ok(v)
}

/// The error of `n` elements of `T` for `what` that the memory cannot hold.
fn no_memory<T>(n: usize, what: &str) -> anyhow::Error {
    let bytes = n as f64 * std::mem::size_of::<T>() as f64;
    anyhow::anyhow!("not enough memory for {what}: {n} of {} bytes ({:.2} GB)", std::mem::size_of::<T>(), bytes / 1e9)
}

/// [`room_for`] `n` elements that the caller fills whole, at once: the
/// pages are mapped in now (`MADV_POPULATE_WRITE`). Not for room sized by untrusted
/// input before its data is seen (a header's count): mapped pages are
/// memory taken, where untouched room is not.
pub fn room_to_fill<T>(n: usize, what: &str) -> Result<Vec<T>> {
    let v = room_for(n, what)?;
    populate(&v);
    Ok(v)
}

/// Room of at least this many bytes is mapped in at once by [`populate`].
const POPULATE_MIN_BYTES: usize = 4 << 20;

/// Maps in the pages of `v`'s room now (Linux 5.14's
/// `MADV_POPULATE_WRITE`), where it is large, in parts on every core: fresh
/// memory taken a page fault at a time cost more than the copies into it
/// (on the H200's virtual machine a million rays' 40 MB of hits took longer
/// to fault in than to trace; here 64 MB in 33-43 ms by faults, 18-21 ms
/// mapped at once). Where the kernel does not have it, the pages fault in
/// as before.
fn populate<T>(v: &Vec<T>) {
    #[cfg(target_os = "linux")]
    {
        use rayon::prelude::*;
        const MADV_POPULATE_WRITE: libc::c_int = 23;
        let bytes = v.capacity().saturating_mul(std::mem::size_of::<T>());
        if bytes < POPULATE_MIN_BYTES {
            return;
        }
        let page = 4096;
        let (start, end) = (v.as_ptr() as usize, v.as_ptr() as usize + bytes);
        let first = start.next_multiple_of(page);
        let len = (end - first) / page * page;
        // Parts of 2 MiB: the kernel zeroes each page it maps, which one
        // core does at a few GB/s.
        let part = 2 << 20;
        (0..len.div_ceil(part)).into_par_iter().for_each(|k| {
            let at = first + k * part;
            // SAFETY: the range lies within `v`'s allocation (whole pages
            // inside it); MADV_POPULATE_WRITE only maps pages in, as writes
            // would, and changes no byte; a failure (an older kernel)
            // changes nothing.
            unsafe {
                libc::madvise(at as *mut libc::c_void, part.min(first + len - at), MADV_POPULATE_WRITE);
            }
        });
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}

/// `n` zeroed elements, or an error naming `what` where the memory cannot
/// hold them ([`room_to_fill`]), written on every core: read-backs, the CPU
/// runner's buffers, Python's arrays of hits. (`calloc` zeroes memory the
/// allocator had freed on one core: on the H200's host, Python's six arrays
/// of a million hits took 5 ms more than the same arrays written again.)
pub fn zeroed_vec<T: bytemuck::Zeroable>(n: usize, what: &str) -> Result<Vec<T>> {
    use rayon::prelude::*;
    use std::mem::MaybeUninit;
    let mut v: Vec<T> = room_to_fill(n, what)?;
    let bytes = n * std::mem::size_of::<T>();
    // SAFETY: the room holds at least `n` elements (`room_for`), seen here
    // as their bytes, which are only written.
    let room = unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast::<MaybeUninit<u8>>(), bytes) };
    room.par_chunks_mut(1 << 20).for_each(|part| part.fill(MaybeUninit::new(0)));
    // SAFETY: the first `n` elements' bytes are now zero, a valid `T`
    // (`Zeroable`).
    unsafe { v.set_len(n) };
    Ok(v)
}

/// Reads the whole of `path` (see [`check`]); never more than the cap,
/// even if the file grows while it is read.
pub fn read(path: &Path, what: &str) -> Result<Vec<u8>> {
    let (file, len) = open(path, what)?;
    let mut bytes = room_to_fill(len as usize, &format!("{what} {}", path.display()))?;
    let max = max_input_bytes();
    // In blocks, so that a watcher can show how far a large file has got.
    let progress = super::progress::track(format!("reading {what} {}", path.display()), len);
    let mut rest = file.take(max.saturating_add(1));
    loop {
        let n = (&mut rest).take(16 << 20).read_to_end(&mut bytes).with_context(|| format!("{what} {}: read error", path.display()))?;
        if n == 0 {
            break;
        }
        progress.add(n as u64);
    }
    drop(progress);
    if bytes.len() as u64 > max {
        bail!("{what} {} grew past the {max} bytes an input may have while it was read", path.display());
    }
    if is_xz(path) {
        return decompress_xz(path, what, &bytes, max);
    }
    Ok(bytes)
}

/// Opens `path` (a `what`) as [`read`] does, for a reader of its own: a
/// regular file within the cap. Returns it and its size.
pub fn open(path: &Path, what: &str) -> Result<(std::fs::File, u64)> {
    check(path, what)?;
    let file = std::fs::File::open(path).with_context(|| format!("{what} {}: cannot open it", path.display()))?;
    // What was opened is checked too: the path may have changed since.
    let len = check_meta(path, what, &file.metadata().with_context(|| format!("{what} {}", path.display()))?)?;
    Ok((file, len))
}

/// Whether `path` names an xz-compressed file (`.xz`), which [`read`]
/// decompresses.
pub fn is_xz(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("xz"))
}

/// `path` without its `.xz`: the name whose extension says what the
/// content is (`mesh.ply.xz` is a PLY mesh).
pub fn content_name(path: &Path) -> std::borrow::Cow<'_, Path> {
    if is_xz(path) { std::borrow::Cow::Owned(path.with_extension("")) } else { std::borrow::Cow::Borrowed(path) }
}

/// The content of the xz file `path` (its bytes read), held to `max` bytes
/// as any input is: a small file may decompress to far more.
fn decompress_xz(path: &Path, what: &str, bytes: &[u8], max: u64) -> Result<Vec<u8>> {
    struct Capped {
        out: Vec<u8>,
        max: u64,
        over: bool,
    }
    impl std::io::Write for Capped {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            if self.out.len() as u64 + buf.len() as u64 > self.max {
                self.over = true;
                return Err(std::io::Error::other("past the cap"));
            }
            self.out.extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let mut capped = Capped { out: Vec::new(), max, over: false };
    match lzma_rs::xz_decompress(&mut std::io::BufReader::new(bytes), &mut capped) {
        Ok(()) => Ok(capped.out),
        Err(_) if capped.over => bail!("{what} {}: decompresses to more than the {max} bytes an input may have", path.display()),
        Err(e) => bail!("{what} {}: not a valid xz file ({e})", path.display()),
    }
}

/// Reads `path` as UTF-8 text (see [`read`]); an error names the line of
/// the first byte that is not text.
pub fn read_text(path: &Path, what: &str) -> Result<String> {
    let mut bytes = read(path, what)?;
    // A byte-order mark, as some editors on Windows write: not part of the text.
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        bytes.drain(..3);
    }
    if bytes.starts_with(b"\xFF\xFE") || bytes.starts_with(b"\xFE\xFF") {
        bail!("{what} {}: UTF-16 text; save it as UTF-8", path.display());
    }
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..at].iter().filter(|&&b| b == b'\n').count();
        anyhow::anyhow!("{what} {}: line {line}: not UTF-8 text (a binary file?)", path.display())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_folders_fifos_devices_and_files_over_the_cap() {
        let dir = std::env::temp_dir().join(format!("treelet-input-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("x.obj")).unwrap();
        let e = format!("{:#}", read(&dir.join("x.obj"), "mesh").unwrap_err());
        assert!(e.contains("is a folder"), "{e}");
        let fifo = dir.join("fifo.obj");
        if std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success()) {
            let e = format!("{:#}", read(&fifo, "mesh").unwrap_err());
            assert!(e.contains("not a regular file"), "{e}");
        }
        let e = format!("{:#}", read(Path::new("/dev/zero"), "mesh").unwrap_err());
        assert!(e.contains("not a regular file"), "{e}");
        let small = dir.join("small.json");
        std::fs::write(&small, "0123456789").unwrap();
        assert_eq!(read(&small, "scene file").unwrap().len(), 10);
        let e = format!("{:#}", read(&dir.join("none.json"), "scene file").unwrap_err());
        assert!(e.contains("none.json") && e.contains("cannot read"), "{e}");
        std::fs::write(dir.join("bin.obj"), b"v 0 0 0\nv \xff\xfe\n").unwrap();
        let e = format!("{:#}", read_text(&dir.join("bin.obj"), "mesh").unwrap_err());
        assert!(e.contains("line 2") && e.contains("not UTF-8"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Room the memory cannot give is an error naming what it was for,
    /// not an abort; room it can give is given.
    #[test]
    fn room_past_the_memory_is_an_error() {
        let e = room_for::<[f32; 12]>(usize::MAX / 16, "the mesh's triangles").unwrap_err().to_string();
        assert!(e.contains("not enough memory for the mesh's triangles") && e.contains("of 48 bytes"), "{e}");
        assert!(room_for::<u64>(1000, "words").unwrap().capacity() >= 1000);
        let e = zeroed_vec::<[f32; 12]>(usize::MAX / 16, "hits").unwrap_err().to_string();
        assert!(e.contains("not enough memory for hits"), "{e}");
    }

    /// Zeroed in parts on every core, whatever the memory held before (a
    /// vector of ones of the same size freed just before).
    #[test]
    fn zeroed_vectors_are_zero() {
        for n in [0, 1, 1000, (3 << 20) + 7] {
            drop(vec![u32::MAX; n]);
            let v = zeroed_vec::<u32>(n, "words").unwrap();
            assert_eq!(v.len(), n);
            assert!(v.iter().all(|&x| x == 0), "{n} words");
            let pairs = zeroed_vec::<[f32; 3]>(n, "triples").unwrap();
            assert!(pairs.len() == n && pairs.iter().all(|p| *p == [0.0; 3]));
        }
    }
}
