//! A level's files: the YAML and glTF files of one level, named and written together,
//! atomically, never replacing a file unless asked. `generate`, `export` and the designer share
//! it.

use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::services::fsio::{self, Overwrite};
use arlpcg_core::level::scene::{PhysicsExtensions, Scene};
use arlpcg_core::level::{Game, Level, gltf, yaml};

/// A level's file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The level file (source of truth; `arlpcg export` and `verify` read it).
    Yaml,
    /// glTF 2.0, one binary file.
    Glb,
    /// glTF 2.0 as JSON with a separate .bin buffer.
    Gltf,
}

/// The files one level is written to: `<dir>/<stem>.<ext>` for each format.
#[derive(Debug, Clone)]
pub struct LevelFiles {
    dir: PathBuf,
    stem: String,
    formats: Vec<Format>,
    gltf: GltfOptions,
}

/// How a level's glTF files carry their colliders; `generate`, `export`, `campaign` and the
/// designer take the same two options, and a campaign's record keeps them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GltfOptions {
    /// Name the solid nodes for Godot's import hints ([`Scene::with_collision_names`]).
    pub collision_names: bool,
    /// The physics extensions written ([`Scene::with_physics_extensions`]; OMI by default).
    pub physics: PhysicsExtensions,
}

impl GltfOptions {
    /// OMI extensions and no import hints: what a file gets unless asked otherwise.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

impl LevelFiles {
    /// The files of a level; repeated formats are written once.
    pub fn new(dir: &Path, stem: &str, formats: &[Format]) -> Self {
        let mut unique = Vec::new();
        for f in formats {
            if !unique.contains(f) {
                unique.push(*f);
            }
        }
        Self {
            dir: dir.to_path_buf(),
            stem: stem.to_string(),
            formats: unique,
            gltf: GltfOptions::default(),
        }
    }

    /// The same files, their glTF carrying colliders as `gltf` says.
    pub fn with_gltf(mut self, gltf: GltfOptions) -> Self {
        self.gltf = gltf;
        self
    }

    fn path(&self, extension: &str) -> PathBuf {
        self.dir.join(format!("{}.{extension}", self.stem))
    }

    /// Every path that will be written.
    pub fn paths(&self) -> Vec<PathBuf> {
        self.formats
            .iter()
            .flat_map(|f| match f {
                Format::Yaml => vec![self.path("yaml")],
                Format::Glb => vec![self.path("glb")],
                Format::Gltf => vec![self.path("gltf"), self.path("bin")],
            })
            .collect()
    }

    /// Fails if any of the files exists and may not be replaced.
    pub fn check_writable(&self, overwrite: Overwrite) -> Result<()> {
        self.paths()
            .iter()
            .try_for_each(|p| fsio::check_writable(p, overwrite))
    }
}

/// The bytes of each file of `files` for `level`, in [`LevelFiles::paths`] order (the same
/// level always gives the same bytes).
pub fn render(level: &Level, files: &LevelFiles) -> Vec<(PathBuf, Vec<u8>)> {
    let scene = || {
        let scene = Scene::of_level(level).with_physics_extensions(files.gltf.physics);
        match files.gltf.collision_names {
            true => scene.with_collision_names(),
            false => scene,
        }
    };
    let mut out = Vec::new();
    for format in &files.formats {
        match format {
            Format::Yaml => out.push((files.path("yaml"), yaml::to_string(level).into_bytes())),
            Format::Glb => out.push((files.path("glb"), gltf::to_glb(&scene()))),
            Format::Gltf => {
                let bin_name = format!("{}.bin", files.stem);
                let output = gltf::to_gltf(&scene(), &bin_name);
                out.push((files.path("gltf"), output.main));
                out.push((files.path("bin"), output.bin));
            }
        }
    }
    out
}

/// Writes the level in each format of `files`, atomically.
pub fn write_level_files(level: &Level, files: &LevelFiles, overwrite: Overwrite) -> Result<()> {
    let mut batch = fsio::FileBatch::new();
    // The .bin before the .gltf that names it.
    for (path, bytes) in render(level, files).iter().rev() {
        batch.stage(path, bytes, overwrite)?;
    }
    batch.commit()
}

/// A level's file name without extension, the same for every writer (`generate`, the
/// designer): `platform_seed7` or, with an aux value, `platform_seed7_aux-0.50`.
pub fn file_stem(game: Game, seed: u64, aux: Option<f64>) -> String {
    match aux {
        // `+ 0.0` turns -0 into +0: `--aux=-0` names its files as `--aux 0` does.
        Some(aux) => format!("{game}_seed{seed}_aux{:+.2}", aux + 0.0),
        None => format!("{game}_seed{seed}"),
    }
}
