//! `arlpcg export`: a level file to glTF.

use std::path::Path;

use anyhow::{Context, Result};

use crate::services::fsio::Overwrite;
use crate::services::level_files::{Format, LevelFiles, write_level_files};
use crate::shells::cli::ExportArgs;
use arlpcg_core::level::yaml;

pub fn run(args: &ExportArgs) -> Result<()> {
    let format = match args.out.extension().and_then(|e| e.to_str()) {
        Some("glb") => Format::Glb,
        Some("gltf") => Format::Gltf,
        _ => {
            return Err(crate::shells::common::UsageError(format!(
                "--out {}: the file name must end in .glb or .gltf",
                args.out.display()
            ))
            .into());
        }
    };
    let level = yaml::load(&args.level)?;
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
    let files = LevelFiles::new(dir, stem, &[format]).with_gltf(args.gltf.into());
    files.check_writable(overwrite)?;
    write_level_files(&level, &files, overwrite)?;
    for path in files.paths() {
        crate::say!("wrote {}", path.display());
    }
    Ok(())
}
