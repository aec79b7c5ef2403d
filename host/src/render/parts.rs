//! Parts of a render made apart (other processes, other machines): each is a
//! linear EXR of per-pixel sums (radiance in r, g, b; squared luminance in
//! a) whose header names the scene, seed, integrator, sampler and sample range.
//! Because Treelet's random numbers are counted from (seed, pixel, sample),
//! parts whose ranges tile `first..last` add up to the render of that range
//! in one go, up to float rounding. `treelet render --samples` writes a
//! part, `treelet merge` adds parts after checking that they belong together.
use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use exr::prelude::*;

use super::image_io::{self, HdrImage};

/// What a part is of.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PartInfo {
    pub scene: String,
    /// [`Scene::content_hash`](crate::scene::Scene::content_hash), as 16 hex digits.
    pub scene_hash: String,
    pub width: u32,
    pub height: u32,
    pub seed: u32,
    pub integrator: String,
    /// `--sampler`'s name (parts written before it was recorded are
    /// `independent`, the only sampler then).
    pub sampler: String,
    /// The samples rendered: `first..last`.
    pub samples: Range<u32>,
    /// Where the render that wrote it was to end (past `samples.end` when
    /// it was stopped early, or wrote it as a checkpoint), so that `merge`
    /// can name samples missing at the end.
    pub planned_end: u32,
}

impl PartInfo {
    /// How `self` is of another render than `other` (scene contents, size,
    /// seed, integrator, sampler), if it is: parts add up only when none differs.
    /// The scene is compared by its contents, not its name: one file named
    /// by two paths is one scene, and a file edited between parts is not.
    pub fn differs_from(&self, other: &PartInfo) -> Option<String> {
        if self.scene_hash != other.scene_hash {
            return Some(format!(
                "one is of scene {} (contents {}), the other of scene {} (contents {}) (was the scene or a mesh edited between them?)",
                self.scene, self.scene_hash, other.scene, other.scene_hash
            ));
        }
        let pairs = [
            ("size", format!("{}x{}", self.width, self.height), format!("{}x{}", other.width, other.height)),
            ("seed", self.seed.to_string(), other.seed.to_string()),
            ("integrator", self.integrator.clone(), other.integrator.clone()),
            ("sampler", self.sampler.clone(), other.sampler.clone()),
        ];
        pairs.into_iter().find(|(_, a, b)| a != b).map(|(what, a, b)| format!("one is of {what} {a}, the other of {b}"))
    }
}

const PREFIX: &str = "treelet.";

/// FNV-1a (64 bits) of the sums' bits, as 16 hex digits: written in a
/// part's header and checked on reading, so that a part damaged on disk
/// or on the way (one flipped byte merged into negative pixels) is an
/// error, not a wrong image.
fn sums_checksum(sums: &[[f32; 4]]) -> String {
    use std::hash::Hasher;
    let mut h = fnv::FnvHasher::default();
    for s in sums {
        for v in s {
            h.write_u32(v.to_bits());
        }
    }
    format!("{:016x}", h.finish())
}

/// Writes `sums` (one per pixel, image order) as a part, atomically.
pub fn write_part(path: &Path, info: &PartInfo, sums: &[[f32; 4]]) -> Result<()> {
    let (w, h) = (info.width as usize, info.height as usize);
    if sums.len() != w * h {
        bail!("{}: {} pixel sums for a {w}x{h} image", path.display(), sums.len());
    }
    let text = |what: &str, v: &str| {
        Text::new_or_none(v).map(AttributeValue::Text).with_context(|| format!("{}: the {what} `{v}` is not Latin-1 text, which EXR headers need", path.display()))
    };
    let mut attributes = LayerAttributes::named("treelet render part");
    let mut put = |key: &str, value: AttributeValue| {
        attributes.other.insert(Text::from(format!("{PREFIX}{key}").as_str()), value);
    };
    put("scene", text("scene name", &info.scene)?);
    put("scene_hash", text("scene hash", &info.scene_hash)?);
    put("integrator", text("integrator", &info.integrator)?);
    put("sampler", text("sampler", &info.sampler)?);
    put("seed", AttributeValue::Text(Text::from(info.seed.to_string().as_str())));
    put("first_sample", AttributeValue::Text(Text::from(info.samples.start.to_string().as_str())));
    put("last_sample", AttributeValue::Text(Text::from(info.samples.end.to_string().as_str())));
    put("planned_last_sample", AttributeValue::Text(Text::from(info.planned_end.to_string().as_str())));
    put("sums_checksum", AttributeValue::Text(Text::from(sums_checksum(sums).as_str())));
    let layer = Layer::new(
        (w, h),
        attributes,
        Encoding::FAST_LOSSLESS,
        SpecificChannels::rgba(|p: Vec2<usize>| {
            let s = sums[p.y() * w + p.x()];
            (s[0], s[1], s[2], s[3])
        }),
    );
    image_io::write_atomically(path, |tmp| Ok(Image::from_layer(layer).write().to_file(tmp)?))
        .with_context(|| format!("cannot write {}", path.display()))
}

/// How many times larger than its file an EXR's pixels may be: deflate's
/// limit (about 1032:1), the best of EXR's lossless compressions.
const MAX_EXR_EXPANSION: u64 = 1100;

/// Zeroed room for `width * height` pixels, or none where a file of
/// `file_bytes` cannot hold them even compressed, or the machine cannot
/// (the caller then reports the header's size). A 900-byte part whose
/// header asked for 300M pixels took 4.7 GB before its data ran out.
fn pixels_or_none(width: usize, height: usize, file_bytes: u64) -> Vec<[f32; 4]> {
    let mut pixels = Vec::new();
    match width.checked_mul(height) {
        Some(n) if (n as u64).saturating_mul(16) <= file_bytes.saturating_mul(MAX_EXR_EXPANSION) && pixels.try_reserve_exact(n).is_ok() => {
            pixels.resize(n, [0f32; 4])
        }
        _ => {}
    }
    pixels
}

/// Reads a part: what it is of, and its sums.
pub fn read_part(path: &Path) -> Result<(PartInfo, Vec<[f32; 4]>)> {
    let file_bytes = crate::internals::input::check(path, "part")?;
    // The header's size is allocated before any pixel is read: a damaged
    // header can ask for petabytes, which must be an error, not an abort.
    let image = read_first_rgba_layer_from_file(
        path,
        move |size, _| (size.width(), pixels_or_none(size.width(), size.height(), file_bytes)),
        |(w, pixels), p, (r, g, b, a): (f32, f32, f32, f32)| {
            if let Some(pixel) = pixels.get_mut(p.y() * *w + p.x()) {
                *pixel = [r, g, b, a];
            }
        },
    )
    .with_context(|| format!("cannot read {} as an EXR image", path.display()))?;
    let size = image.layer_data.size;
    if image.layer_data.channel_data.pixels.1.len() != size.width() * size.height() {
        bail!(
            "{}: its header says {}x{} pixels, more than a file of {file_bytes} bytes holds (or this machine can)",
            path.display(),
            size.width(),
            size.height()
        );
    }
    let other = &image.layer_data.attributes.other;
    let field = |key: &str| -> Result<String> {
        match other.get(&Text::from(format!("{PREFIX}{key}").as_str())) {
            Some(AttributeValue::Text(t)) => Ok(t.to_string()),
            _ => bail!("{}: no `{PREFIX}{key}` in its header: not a part written by `treelet render --samples`", path.display()),
        }
    };
    let number = |key: &str| -> Result<u32> {
        let v = field(key)?;
        v.parse().with_context(|| format!("{}: `{PREFIX}{key}` is `{v}`, not a number", path.display()))
    };
    let info = PartInfo {
        scene: field("scene")?,
        scene_hash: field("scene_hash")?,
        width: size.width() as u32,
        height: size.height() as u32,
        seed: number("seed")?,
        integrator: field("integrator")?,
        sampler: if other.contains_key(&Text::from(format!("{PREFIX}sampler").as_str())) { field("sampler")? } else { "independent".into() },
        samples: number("first_sample")?..number("last_sample")?,
        planned_end: 0,
    };
    // Parts written before it was recorded were planned to their own end.
    let planned_end = if other.contains_key(&Text::from(format!("{PREFIX}planned_last_sample").as_str())) { number("planned_last_sample")? } else { info.samples.end };
    let info = PartInfo { planned_end: planned_end.max(info.samples.end), ..info };
    if info.samples.is_empty() {
        bail!("{}: its sample range {}..{} is empty", path.display(), info.samples.start, info.samples.end);
    }
    let sums = image.layer_data.channel_data.pixels.1;
    // Parts written before the checksum was recorded have none to check.
    if other.contains_key(&Text::from(format!("{PREFIX}sums_checksum").as_str())) {
        let (recorded, found) = (field("sums_checksum")?, sums_checksum(&sums));
        if recorded != found {
            bail!("{}: its pixel sums do not match the checksum in its header ({found}, not {recorded}): the file was damaged after it was written", path.display());
        }
    }
    Ok((info, sums))
}

/// Reads an image to be scored (`compare`, `render --reference`): a part
/// holds per-pixel sums, not means, so it is refused (merge it first), and
/// so is an image with a NaN or infinite pixel, which no error is defined
/// for. `what` names the image in errors.
pub fn read_scored_image(path: &Path, what: &str) -> Result<HdrImage> {
    if image_io::extension(path) == "exr" && read_part(path).is_ok() {
        bail!(
            "{what} {} is a render part (per-pixel sums of a sample range), not an image: `treelet merge` it into one first",
            path.display()
        );
    }
    let image = image_io::read_hdr(path)?;
    if let Some(i) = image.pixels.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
        let (x, y) = (i as u32 % image.width, i as u32 / image.width);
        bail!("{what} {}: pixel ({x}, {y}) is {:?}: not finite, so no error can be measured", path.display(), image.pixels[i]);
    }
    Ok(image)
}

/// Adds parts: they must be of one scene, size, seed and integrator, and
/// their sample ranges must neither overlap nor leave gaps. Returns what
/// the sum is of (its range: the union; its planned end: the furthest any
/// part was planned to), and the image of mean radiance.
pub fn merge(paths: &[PathBuf]) -> Result<(PartInfo, HdrImage)> {
    let Some(first) = paths.first() else { bail!("no parts to merge") };
    let mut parts = Vec::new();
    for p in paths {
        let (info, sums) = read_part(p)?;
        parts.push((p, info, sums));
    }
    let reference = parts[0].1.clone();
    for (p, info, _) in &parts[1..] {
        if let Some(why) = info.differs_from(&reference) {
            bail!("{} and {} are not parts of one render: {why}", p.display(), first.display());
        }
    }
    parts.sort_by_key(|(_, info, _)| info.samples.start);
    for pair in parts.windows(2) {
        let ((a, ia, _), (b, ib, _)) = (&pair[0], &pair[1]);
        if ib.samples.start < ia.samples.end {
            bail!(
                "{} (samples {}..{}) and {} (samples {}..{}) overlap",
                a.display(),
                ia.samples.start,
                ia.samples.end,
                b.display(),
                ib.samples.start,
                ib.samples.end
            );
        }
        if ib.samples.start > ia.samples.end {
            bail!(
                "samples {}..{} are missing: between {} (..{}) and {} ({}..)",
                ia.samples.end,
                ib.samples.start,
                a.display(),
                ia.samples.end,
                b.display(),
                ib.samples.start
            );
        }
    }
    let samples = parts[0].1.samples.start..parts[parts.len() - 1].1.samples.end;
    let mut sums = vec![[0f64; 4]; parts[0].2.len()];
    for (_, _, part) in &parts {
        super::sums::add_sums(&mut sums, part);
    }
    let image = super::sums::mean_image(reference.width, reference.height, &sums, samples.end - samples.start);
    let planned_end = parts.iter().map(|p| p.1.planned_end).max().unwrap_or(samples.end);
    Ok((PartInfo { samples, planned_end, ..reference }, image))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 900-byte part found by the fuzz target `part` (kept in
    /// `tests/corpus/regressions/part/`), whose header asks for far more
    /// pixels than its bytes hold: no room is made for them (it took 4.7 GB
    /// and 8 s before its data ran out; now the EXR reader's error at once).
    #[test]
    fn a_header_larger_than_its_file_is_refused_before_its_room_is_made() {
        let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/corpus/regressions/part/header_asks_for_gigabytes"));
        let dir = std::env::temp_dir().join(format!("treelet-part-big-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let part = dir.join("part.exr");
        std::fs::copy(path, &part).unwrap();
        // The process's peak resident memory (Linux), before and after.
        let peak_kb = || -> u64 {
            let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
            status.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| l.split_whitespace().nth(1)?.parse().ok()).unwrap_or(0)
        };
        let before = peak_kb();
        let e = format!("{:#}", read_part(&part).unwrap_err());
        assert!(e.contains("part.exr"), "{e}");
        let grown_mb = peak_kb().saturating_sub(before) / 1024;
        assert!(grown_mb < 512, "reading a 900-byte part raised the peak memory by {grown_mb} MB");
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Room for a header's pixels is asked for, not assumed: a damaged
    /// header found by `tests/fuzz.rs` asked for 49 PB, and `vec!` aborts.
    #[test]
    fn room_for_impossible_sizes_is_refused() {
        assert_eq!(pixels_or_none(3, 2, 1000).len(), 6);
        // Past what a file of 1 000 bytes holds, even compressed.
        assert!(pixels_or_none(1000, 1000, 1000).is_empty());
        assert!(pixels_or_none(1 << 31, 1 << 31, u64::MAX).is_empty());
        assert!(pixels_or_none(usize::MAX, 2, u64::MAX).is_empty());
    }

    /// A part records its sampler, reads it back, and parts of two samplers
    /// are not parts of one render (their sample points differ).
    #[test]
    fn parts_record_their_sampler() {
        let dir = std::env::temp_dir().join(format!("treelet-part-sampler-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("part.exr");
        let info = PartInfo {
            scene: "cornell".into(),
            scene_hash: "0".into(),
            width: 3,
            height: 2,
            seed: 1,
            integrator: "nee".into(),
            sampler: "sobol".into(),
            samples: 0..4,
            planned_end: 4,
        };
        write_part(&path, &info, &[[1.0; 4]; 6]).unwrap();
        let (back, _) = read_part(&path).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(back.sampler, "sobol");
        assert!(back.differs_from(&info).is_none());
        let why = back.differs_from(&PartInfo { sampler: "independent".into(), ..info }).expect("two samplers differ");
        assert!(why.contains("sampler sobol") && why.contains("independent"), "{why}");
    }

    /// Every byte of a part flipped in turn: each damaged file
    /// is refused (by the checksum, or as a broken EXR), never read as other
    /// sums; a part whose header records another checksum is named damaged.
    #[test]
    fn a_damaged_part_is_refused() {
        let dir = std::env::temp_dir().join(format!("treelet-part-damaged-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("part.exr");
        let info = PartInfo {
            scene: "cornell".into(),
            scene_hash: "0".into(),
            width: 5,
            height: 4,
            seed: 1,
            integrator: "nee".into(),
            sampler: "sobol".into(),
            samples: 0..4,
            planned_end: 4,
        };
        let sums: Vec<[f32; 4]> = (0..20).map(|k| [k as f32 * 0.37, 1.0 + k as f32, 2.5, k as f32 * k as f32]).collect();
        write_part(&path, &info, &sums).unwrap();
        let good = std::fs::read(&path).unwrap();
        assert_eq!(read_part(&path).unwrap().1, sums);
        // Header and data alike: a flip may leave the sums as they were
        // (a byte of the scene's name), never make other sums.
        let mut refused = 0;
        for at in 0..good.len() {
            let mut bad = good.clone();
            bad[at] ^= 0x10;
            std::fs::write(&path, &bad).unwrap();
            match read_part(&path) {
                Err(_) => refused += 1,
                Ok((_, back)) => assert_eq!(back, sums, "byte {at} flipped was read as other sums"),
            }
        }
        assert!(refused > 0);
        // A header recording another checksum.
        let recorded = sums_checksum(&sums);
        let at = good.windows(recorded.len()).position(|w| w == recorded.as_bytes()).unwrap();
        let mut bad = good.clone();
        bad[at] = if bad[at] == b'0' { b'1' } else { b'0' };
        std::fs::write(&path, &bad).unwrap();
        let e = format!("{:#}", read_part(&path).unwrap_err());
        let _ = std::fs::remove_dir_all(&dir);
        assert!(e.contains("part.exr") && e.contains("damaged"), "{e}");
    }

    /// A header whose data window asks for more pixels than the file holds:
    /// an error that names the file.
    #[test]
    fn a_huge_data_window_is_an_error() {
        let dir = std::env::temp_dir().join(format!("treelet-part-window-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("part.exr");
        let info = PartInfo {
            scene: "cornell".into(),
            scene_hash: "0".into(),
            width: 3,
            height: 2,
            seed: 1,
            integrator: "nee".into(),
            sampler: "sobol".into(),
            samples: 0..4,
            planned_end: 4,
        };
        write_part(&path, &info, &[[1.0; 4]; 6]).unwrap();
        assert!(read_part(&path).is_ok());
        // dataWindow: name, type "box2i", size 16, then xMin yMin xMax yMax.
        let mut bytes = std::fs::read(&path).unwrap();
        let name = b"dataWindow\0box2i\0";
        let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + name.len() + 4;
        bytes[at..at + 4].copy_from_slice(&(-0x3fff_ffffi32).to_le_bytes());
        bytes[at + 8..at + 12].copy_from_slice(&0x3fff_ffffi32.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read_part(&path).unwrap_err();
        let _ = std::fs::remove_dir_all(&dir);
        assert!(format!("{err:#}").contains("part.exr"), "{err:#}");
    }
}
