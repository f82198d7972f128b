//! `arlpcg export-policy`: a trained policy's actor as an ONNX graph with a JSON sidecar.

use anyhow::{Context, Result};

use crate::cli::ExportPolicyArgs;
use crate::fsio::{Batch, Overwrite};
use crate::rl::checkpoint::{MAX_POLICY_BYTES, Role, read_card};

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
    let bytes = crate::fsio::read_limited(&args.policy, MAX_POLICY_BYTES, "policy")?;
    let card = read_card(&bytes).with_context(|| format!("{}", args.policy.display()))?;
    // Loaded through the game's own loader: game, role, shape and normalizer all checked.
    let (policy, card, reference) = match card.role {
        Role::Solver => {
            let (solver, card) = crate::policies::load_solver(&args.policy, card.game)?;
            (solver.policy, card, solver.reference)
        }
        Role::Generator => {
            let (generator, card) = crate::policies::load_generator(&args.policy, card.game)?;
            (generator.policy, card, generator.reference)
        }
    };
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
