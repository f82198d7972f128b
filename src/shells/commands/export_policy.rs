//! `arlpcg export-policy`: a trained policy's actor as an ONNX graph with a JSON sidecar.

use anyhow::{Context, Result};

use crate::services::fsio::{FileBatch, Overwrite};
use crate::shells::cli::ExportPolicyArgs;

pub fn run(args: &ExportPolicyArgs) -> Result<()> {
    if args.out.extension().and_then(|e| e.to_str()) != Some("onnx") {
        return Err(crate::shells::common::UsageError(format!(
            "--out {}: the file name must end in .onnx",
            args.out.display()
        ))
        .into());
    }
    let sidecar_path = crate::services::onnx::sidecar_path(&args.out);
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    for path in [&args.out, &sidecar_path] {
        crate::services::fsio::check_writable(path, overwrite)?;
    }
    // Loaded through the game's own loader: game, role, shape and normalizer all checked.
    let (policy, card, reference) = crate::services::policies::load_any(&args.policy)?;
    let exported = crate::services::onnx::export(&policy, &card, reference, args.profile)
        .with_context(|| format!("{}: exporting the actor", args.policy.display()))?;
    let sidecar = serde_json::to_string_pretty(&exported.sidecar)? + "\n";
    let mut batch = FileBatch::new();
    batch.stage(&args.out, &exported.onnx, overwrite)?;
    batch.stage(&sidecar_path, sidecar.as_bytes(), overwrite)?;
    batch.commit()?;
    crate::say!(
        "wrote {} ({} {}, profile {}, opset {}) and {}",
        args.out.display(),
        card.game,
        card.role,
        args.profile.name(),
        crate::services::onnx::OPSET,
        sidecar_path.display()
    );
    Ok(())
}
