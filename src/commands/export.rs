//! `arlpcg export`: a level file to glTF; and the writer of a level's files that `generate`
//! shares.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use crate::cli::{ExportArgs, Format};
use crate::fsio::{self, Overwrite};
use crate::level::scene::Scene;
use crate::level::{Level, gltf, yaml};

pub fn run(args: &ExportArgs) -> Result<()> {
    let level = yaml::load(&args.level)?;
    let format = match args.out.extension().and_then(|e| e.to_str()) {
        Some("glb") => Format::Glb,
        Some("gltf") => Format::Gltf,
        _ => bail!(
            "--out {}: the file name must end in .glb or .gltf",
            args.out.display()
        ),
    };
    let stem = args
        .out
        .file_stem()
        .and_then(|s| s.to_str())
        .context("--out has no file name")?;
    let dir = args
        .out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    let files = LevelFiles::new(dir, stem, &[format]);
    files.check_writable(overwrite)?;
    write_level_files(&level, &files, overwrite)?;
    for path in files.paths() {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The files one level is written to: `<dir>/<stem>.<ext>` for each format.
#[derive(Debug, Clone)]
pub struct LevelFiles {
    dir: PathBuf,
    stem: String,
    formats: Vec<Format>,
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
        }
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

/// Writes the level in each format of `files`, atomically.
pub fn write_level_files(level: &Level, files: &LevelFiles, overwrite: Overwrite) -> Result<()> {
    let scene = || Scene::of_level(level);
    for format in &files.formats {
        match format {
            Format::Yaml => fsio::write_atomic(
                &files.path("yaml"),
                yaml::to_string(level).as_bytes(),
                overwrite,
            )?,
            Format::Glb => {
                fsio::write_atomic(&files.path("glb"), &gltf::to_glb(&scene()), overwrite)?
            }
            Format::Gltf => {
                let bin_name = format!("{}.bin", files.stem);
                let output = gltf::to_gltf(&scene(), &bin_name);
                fsio::write_atomic(&files.path("bin"), &output.bin, overwrite)?;
                fsio::write_atomic(&files.path("gltf"), &output.main, overwrite)?;
            }
        }
    }
    Ok(())
}
