//! Scene files compiled into the binary, so that `--scene room_disk` and the
//! benchmarks that use them run from any folder (issue 69). Each is the
//! file of the same name in `scenes/`, which stays the one to read and edit.
use anyhow::Result;

use super::model::Scene;

/// Name, and the text of `scenes/<name>.json`. None names a mesh file.
pub const BUILT_IN: [(&str, &str); 3] = [
    ("room_disk", include_str!("../../scenes/room_disk.json")),
    ("cornell_diffuse", include_str!("../../scenes/cornell_diffuse.json")),
    ("cornell_mirrors", include_str!("../../scenes/cornell_mirrors.json")),
];

/// The built-in scene file called `name`, parsed; `None` for other names.
pub fn scene(name: &str) -> Option<Result<Scene>> {
    BUILT_IN.iter().find(|(n, _)| *n == name).map(|(n, text)| super::file::parse(text, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_scenes_parse_and_match_their_files() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes");
        for (name, text) in BUILT_IN {
            let scene = scene(name).unwrap().unwrap();
            assert!(!scene.materials.is_empty(), "{name}");
            let file = std::fs::read_to_string(format!("{dir}/{name}.json")).unwrap();
            assert_eq!(text, file, "{name}");
        }
        assert!(scene("no_such_scene").is_none());
    }
}
