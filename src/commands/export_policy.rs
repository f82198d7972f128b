//! `arlpcg export-policy`: a trained policy's actor as an ONNX graph with a JSON sidecar.

use anyhow::{Context, Result};

use crate::cli::ExportPolicyArgs;
use crate::fsio::{Batch, Overwrite};

pub fn run(args: &ExportPolicyArgs) -> Result<()> {
    if args.out.extension().and_then(|e| e.to_str()) != Some("onnx") {
        return Err(crate::shell::UsageError(format!(
            "--out {}: the file name must end in .onnx",
            args.out.display()
        ))
        .into());
    }
    let sidecar_path = crate::onnx::sidecar_path(&args.out);
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    for path in [&args.out, &sidecar_path] {
        crate::fsio::check_writable(path, overwrite)?;
    }
    // Loaded through the game's own loader: game, role, shape and normalizer all checked.
    let (policy, card, reference) = crate::policies::load_any(&args.policy)?;
    let exported = crate::onnx::export(&policy, &card, reference, args.profile)
        .with_context(|| format!("{}: exporting the actor", args.policy.display()))?;
    let sidecar = serde_json::to_string_pretty(&exported.sidecar)? + "\n";
    let mut batch = Batch::new();
    batch.stage(&args.out, &exported.onnx, overwrite)?;
    batch.stage(&sidecar_path, sidecar.as_bytes(), overwrite)?;
    batch.commit()?;
    println!(
        "wrote {} ({} {}, profile {}, opset {}) and {}",
        args.out.display(),
        card.game,
        card.role,
        args.profile.name(),
        crate::onnx::OPSET,
        sidecar_path.display()
    );
    Ok(())
}
