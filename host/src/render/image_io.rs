//! Images in and out: PNG (gamma 2.2 and clamped, as smallpt writes them),
//! and linear HDR as OpenEXR (through the `image` crate) or PFM.
//!
//! PFM (Portable Float Map) has no maintained crate; its whole format is a
//! three-line text header (`PF`, `width height`, a negative scale for
//! little-endian) and rows of f32 RGB from the bottom up, written here.
use std::path::Path;

use anyhow::{bail, Context as _, Result};

/// A linear RGB image, rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

/// smallpt's `toInt`: clamp to [0, 1], gamma 2.2, round.
pub fn to_srgb8(x: f32) -> u8 {
    (x.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0 + 0.5) as u8
}

pub fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// The formats [`write()`] takes, by extension.
pub const IMAGE_FORMATS: [&str; 3] = ["png", "exr", "pfm"];

/// Checks, before any work is done, that `path` can be written as the
/// output `what` (`--out`, `--report`): its extension is one of `formats`
/// (any, if empty), it is not a folder, its folder exists and takes new
/// files, and an existing file there can be opened for writing. Nothing is
/// written or truncated.
pub fn check_output(path: &Path, what: &str, formats: &[&str]) -> Result<()> {
    let ext = extension(path);
    if !formats.is_empty() && !formats.contains(&ext.as_str()) {
        let list = formats.iter().map(|f| format!(".{f}")).collect::<Vec<_>>().join(", ");
        if ext.is_empty() {
            bail!("{what} {}: no file extension (name a {list} file)", path.display());
        }
        bail!("{what} {}: unknown image format `.{ext}` (use {list})", path.display());
    }
    if path.is_dir() {
        bail!("{what} {} is a folder: name a file", path.display());
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => bail!("{what} {}: {} is a file, not a folder", path.display(), dir.display()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            bail!("{what} {}: the folder {} does not exist", path.display(), dir.display())
        }
        Err(e) => bail!("{what} {}: cannot reach the folder {}: {e}", path.display(), dir.display()),
    }
    // A device or a pipe (`/dev/stdout`, `/dev/null`) is written in place
    // (see `write_atomically`): no probe file beside it, and a pipe is not
    // opened now (that would wait for a reader).
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        return Ok(());
    }
    // Whether the folder takes new files: a probe, removed at once.
    let probe = dir.join(format!(".treelet-write-check-{}", std::process::id()));
    std::fs::File::create(&probe).with_context(|| format!("{what} {}: cannot create files in {}", path.display(), dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    if path.exists() {
        std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .with_context(|| format!("{what} {}: the file exists and cannot be written", path.display()))?;
    }
    Ok(())
}

/// Writes a file by `write` into a temporary file beside `path` (with the
/// same extension), then renames it over `path`: a crash or a failed write
/// never leaves a half-written file where a good one was. Where `path`
/// names something that is not a regular file (a device such as
/// `/dev/stdout`, a pipe), it is written in place: a rename would replace
/// the device node or link itself. A link to a regular file keeps being a
/// link: the file it names is replaced.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        // A FIFO's reader is held open by `_reader_seen` while it is written.
        let _reader_seen = wait_for_reader(path, FIFO_READER_WAIT)?;
        return write(path);
    }
    let resolved = match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path).ok(),
        _ => None,
    };
    let path = resolved.as_deref().unwrap_or(path);
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    let suffix = path.extension().map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(&suffix);
    // As a plain create would make it (0666 less the umask), not tempfile's 0600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let tmp = builder.tempfile_in(dir).with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
    write(tmp.path())?;
    tmp.persist(path).map_err(|e| anyhow::anyhow!("cannot rename the finished file over it: {}", e.error))?;
    Ok(())
}

/// How long a finished render waits for a reader of a FIFO it writes to.
const FIFO_READER_WAIT: std::time::Duration = std::time::Duration::from_secs(60);

/// Where `path` is a FIFO: waits up to `wait` for a process to read it, and
/// returns it opened for writing without blocking (held while the output is
/// written, so the reader sees one stream); an error naming the FIFO if none
/// came. A plain open would block for ever with no reader (as a shell's
/// `> fifo` does), after a render that may have taken hours. Anything else:
/// nothing to wait for.
#[cfg(unix)]
fn wait_for_reader(path: &Path, wait: std::time::Duration) -> Result<Option<std::fs::File>> {
    use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
    if !std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo()) {
        return Ok(None);
    }
    let start = std::time::Instant::now();
    let mut noted = false;
    loop {
        match std::fs::OpenOptions::new().write(true).custom_flags(libc::O_NONBLOCK).open(path) {
            Ok(f) => return Ok(Some(f)),
            // ENXIO: no reader yet.
            Err(e) if e.raw_os_error() == Some(libc::ENXIO) => {
                if start.elapsed() >= wait {
                    bail!("{} is a FIFO and nothing read it for {} s: start its reader (e.g. `cat {0} > file`), or write to a file", path.display(), wait.as_secs());
                }
                if !noted {
                    eprintln!("note: waiting up to {} s for a reader of the FIFO {}", wait.as_secs(), path.display());
                    noted = true;
                }
                std::thread::sleep(std::time::Duration::from_millis(50));
            }
            Err(e) => bail!("cannot open the FIFO {} for writing: {e}", path.display()),
        }
    }
}

#[cfg(not(unix))]
fn wait_for_reader(_path: &Path, _wait: std::time::Duration) -> Result<Option<std::fs::File>> {
    Ok(None)
}

/// Writes `image` in the format its extension names (.png, .exr or .pfm),
/// atomically ([`write_atomically`]).
pub fn write(path: &Path, image: &HdrImage) -> Result<()> {
    write_atomically(path, |tmp| write_format(tmp, &extension(path), image))
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Writes `image` to `path` in the format `ext`.
fn write_format(path: &Path, ext: &str, image: &HdrImage) -> Result<()> {
    let (w, h) = (image.width, image.height);
    match ext {
        "png" => {
            use image::codecs::png::{CompressionType, FilterType, PngEncoder};
            use rayon::prelude::*;
            let bytes: Vec<u8> = image.pixels.par_iter().flat_map_iter(|p| p.map(to_srgb8)).collect();
            // Fast compression: a render's PNG is written on every run, and the
            // default level takes several times longer for a few percent of size.
            let file = std::fs::File::create(path)?;
            let encoder = PngEncoder::new_with_quality(std::io::BufWriter::new(file), CompressionType::Fast, FilterType::Adaptive);
            image::ImageEncoder::write_image(encoder, &bytes, w, h, image::ExtendedColorType::Rgb8)
                .context("encoding failed")
        }
        "exr" => {
            let floats: Vec<f32> = image.pixels.iter().flatten().copied().collect();
            image::Rgb32FImage::from_raw(w, h, floats)
                .context("image size mismatch")?
                .save_with_format(path, image::ImageFormat::OpenExr)
                .context("encoding failed")
        }
        "pfm" => {
            let mut out = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
            for row in image.pixels.chunks(w as usize).rev() {
                for v in row.iter().flatten() {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
            std::fs::write(path, out).map_err(Into::into)
        }
        other => bail!("unknown image format `.{other}` (use .png, .exr or .pfm)"),
    }
}

/// Reads a linear HDR image (.exr or .pfm).
pub fn read_hdr(path: &Path) -> Result<HdrImage> {
    crate::internals::input::check(path, "image")?;
    match extension(path).as_str() {
        "exr" => {
            let img = image::open(path).with_context(|| format!("cannot read {}", path.display()))?.into_rgb32f();
            let (width, height) = img.dimensions();
            let pixels = img.pixels().map(|p| p.0).collect();
            Ok(HdrImage { width, height, pixels })
        }
        "pfm" => {
            let bytes = crate::internals::input::read(path, "image")?;
            parse_pfm(&bytes).with_context(|| format!("{}: not a valid colour PFM file", path.display()))
        }
        other => bail!("{}: a reference must be .exr or .pfm, not `.{other}`", path.display()),
    }
}

/// Parses a colour PFM (`PF`), either byte order.
pub fn parse_pfm(bytes: &[u8]) -> Result<HdrImage> {
    // The header is three whitespace-separated tokens after "PF", then one
    // whitespace byte, then the data.
    let mut tokens = Vec::new();
    let mut pos = 0;
    while tokens.len() < 4 {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos {
            bail!("header ends early");
        }
        tokens.push(std::str::from_utf8(&bytes[start..pos]).context("header is not text")?);
    }
    pos += 1; // the single whitespace byte after the scale
    if tokens[0] != "PF" {
        bail!("starts with `{}`, expected `PF` (colour PFM)", tokens[0]);
    }
    let width: u32 = tokens[1].parse().context("bad width")?;
    let height: u32 = tokens[2].parse().context("bad height")?;
    let scale: f32 = tokens[3].parse().context("bad scale")?;
    // Its sign says the byte order; 0 or NaN says neither (and were read as
    // big-endian, so an image equal to its reference scored an error of 0.5).
    if !(scale.is_finite() && scale != 0.0) {
        bail!("scale {scale}: its sign gives the byte order, so it must be a non-zero number");
    }
    if width == 0 || height == 0 {
        bail!("empty image {width}x{height}");
    }
    let count = width as usize * height as usize * 3;
    let data = bytes.get(pos..).unwrap_or(&[]);
    if data.len() != count * 4 {
        bail!("{} bytes of pixel data, expected {} for {width}x{height}", data.len(), count * 4);
    }
    let floats: Vec<f32> = data
        .as_chunks::<4>()
        .0
        .iter()
        .map(|&b| if scale < 0.0 { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) })
        .collect();
    let mut pixels: Vec<[f32; 3]> = floats.as_chunks::<3>().0.to_vec();
    // Bottom-up rows to top-down.
    let rows: Vec<Vec<[f32; 3]>> = pixels.chunks(width as usize).rev().map(|r| r.to_vec()).collect();
    pixels = rows.concat();
    Ok(HdrImage { width, height, pixels })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> HdrImage {
        let pixels = (0..6).map(|i| [i as f32, 0.5 * i as f32, 100.0 - i as f32]).collect();
        HdrImage { width: 3, height: 2, pixels }
    }

    #[test]
    fn pfm_and_exr_round_trip() {
        let dir = std::env::temp_dir().join(format!("treelet-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for ext in ["pfm", "exr"] {
            let path = dir.join(format!("a.{ext}"));
            write(&path, &sample()).unwrap();
            assert_eq!(read_hdr(&path).unwrap(), sample(), "{ext}");
        }
        write(&dir.join("a.png"), &sample()).unwrap();
        assert!(format!("{:#}", write(&dir.join("a.bmp"), &sample()).unwrap_err()).contains("unknown image format"));
    }

    /// An output that is a FIFO: with no reader, an error naming it after the
    /// wait (it used to block for ever); with one, the image reaches it whole.
    #[cfg(unix)]
    #[test]
    fn a_fifo_output_waits_for_its_reader() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("out.pfm");
        let name = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0, "mkfifo");
        let start = std::time::Instant::now();
        let e = wait_for_reader(&fifo, std::time::Duration::from_millis(300)).unwrap_err().to_string();
        assert!(e.contains("is a FIFO") && e.contains("out.pfm") && e.contains("nothing read it"), "{e}");
        assert!(start.elapsed() < std::time::Duration::from_secs(5), "{:?}", start.elapsed());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(&fifo).unwrap())
        };
        write(&fifo, &sample()).unwrap();
        let bytes = reader.join().unwrap();
        assert_eq!(parse_pfm(&bytes).unwrap(), sample());
        // A plain file is not waited for.
        assert!(wait_for_reader(&dir.path().join("new.pfm"), std::time::Duration::ZERO).unwrap().is_none());
    }

    #[test]
    fn malformed_pfm_is_an_error() {
        assert!(parse_pfm(b"P6\n1 1\n255\n\0\0\0").is_err());
        assert!(parse_pfm(b"PF\n2 2\n-1.0\n\0\0\0\0").unwrap_err().to_string().contains("bytes of pixel data"));
        assert!(parse_pfm(b"PF\n2").is_err());
        for scale in ["0", "nan", "-0.0"] {
            let text = format!("PF\n1 1\n{scale}\n");
            let bytes = [text.as_bytes(), &[0u8; 12]].concat();
            assert!(parse_pfm(&bytes).unwrap_err().to_string().contains("non-zero"), "scale {scale}");
        }
    }

    #[test]
    fn smallpt_gamma() {
        assert_eq!(to_srgb8(0.0), 0);
        assert_eq!(to_srgb8(1.0), 255);
        assert_eq!(to_srgb8(7.0), 255);
        assert_eq!(to_srgb8(0.5), 186);
    }

    /// A write that fails half-way leaves the file that was there whole,
    /// and no temporary file beside it.
    #[test]
    fn a_failed_write_leaves_the_old_file() {
        let dir = std::env::temp_dir().join(format!("treelet-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.pfm");
        write(&path, &sample()).unwrap();
        let before = std::fs::read(&path).unwrap();
        let e = write_atomically(&path, |tmp| {
            std::fs::write(tmp, b"PF\n2 1\n")?;
            bail!("disk full")
        });
        assert!(format!("{:#}", e.unwrap_err()).contains("disk full"));
        assert_eq!(std::fs::read(&path).unwrap(), before);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "only a.pfm is left");
        let _ = std::fs::remove_dir_all(&dir);
    }
}