//! `arlpcg export-policy`: a trained policy's actor as an ONNX graph with a JSON sidecar.

use anyhow::{Context, Result};

use arlpcg_core::rl::checkpoint::Role;

use crate::services::fsio::{FileBatch, Overwrite};
use crate::services::onnx::golden::{generator_golden_episode, generator_rules, golden_episode};
use crate::shells::cli::ExportPolicyArgs;

pub fn run(args: &ExportPolicyArgs) -> Result<()> {
    match args.out.extension().and_then(|e| e.to_str()) {
        Some("onnx") => {}
        Some("json") => return web(args),
        _ => {
            return Err(crate::shells::common::UsageError(format!(
                "--out {}: the file name must end in .onnx (the graph) or .json (a Generator's \
                 numbers for web/network.mjs)",
                args.out.display()
            ))
            .into());
        }
    }
    let sidecar_path = crate::services::onnx::sidecar_path(&args.out);
    let golden_path = crate::services::onnx::golden::golden_path(&args.out);
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    for path in [&args.out, &sidecar_path, &golden_path] {
        crate::services::fsio::check_writable(path, overwrite)?;
    }
    // Loaded through the game's own loader: game, role, shape and normalizer all checked.
    let (policy, card, reference) = crate::services::policies::load_any(&args.policy)?;
    let mut exported = crate::services::onnx::export(&policy, &card, reference, args.contract)
        .with_context(|| format!("{}: exporting the actor", args.policy.display()))?;
    // The policy's golden episode, for a port of its observation (docs/engines.md).
    let golden = match card.role {
        Role::Solver => {
            let reference = exported.sidecar.policy.clone();
            let episode =
                arlpcg_core::for_game!(card.game, G => golden_episode::<G>(&policy, &card, reference))
            .with_context(|| format!("{}: playing its golden episode", args.policy.display()))?;
            Some(serde_json::to_string(&episode)? + "\n")
        }
        Role::Generator => {
            let reference = exported.sidecar.policy.clone();
            let limits = crate::services::policies::generator_limits(&args.policy, &card)?;
            let episode = arlpcg_core::for_game!(card.game, G => {
                generator_golden_episode::<G>(&policy, &card, reference, limits)
            })
            .with_context(|| format!("{}: building its golden episode", args.policy.display()))?;
            // What `generate` reads besides the graph, for a port that builds levels.
            exported.sidecar.generator = Some(generator_rules(card.game, limits));
            Some(serde_json::to_string(&episode)? + "\n")
        }
    };
    let sidecar = serde_json::to_string_pretty(&exported.sidecar)? + "\n";
    let mut batch = FileBatch::new();
    batch.stage(&args.out, &exported.onnx, overwrite)?;
    batch.stage(&sidecar_path, sidecar.as_bytes(), overwrite)?;
    if let Some(golden) = &golden {
        batch.stage(&golden_path, golden.as_bytes(), overwrite)?;
    }
    batch.commit()?;
    let golden = match golden {
        Some(_) => format!(" and its golden episode {}", golden_path.display()),
        None => String::new(),
    };
    crate::say!(
        "wrote {} ({} {}, contract {}, opset {}), {}{golden}",
        args.out.display(),
        card.game,
        card.role,
        args.contract.name(),
        crate::services::onnx::OPSET,
        sidecar_path.display()
    );
    Ok(())
}

/// `--out G.json`: a Generator's sidecar and actor as numbers, for `web/network.mjs`.
fn web(args: &ExportPolicyArgs) -> Result<()> {
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    crate::services::fsio::check_writable(&args.out, overwrite)?;
    let (policy, card, reference) = crate::services::policies::load_any(&args.policy)?;
    if card.role != Role::Generator || args.contract != crate::services::onnx::Contract::Plain {
        return Err(crate::shells::common::UsageError(format!(
            "--out {}: numbers for a web page are written for a Generator in the plain \
             contract; {} is a {} (write .onnx for it)",
            args.out.display(),
            args.policy.display(),
            card.role
        ))
        .into());
    }
    let limits = crate::services::policies::generator_limits(&args.policy, &card)?;
    let numbers = crate::services::onnx::web::web_generator(&policy, &card, reference, limits)
        .with_context(|| format!("{}", args.policy.display()))?
        + "\n";
    let mut batch = FileBatch::new();
    batch.stage(&args.out, numbers.as_bytes(), overwrite)?;
    batch.commit()?;
    crate::say!(
        "wrote {} ({} generator: its sidecar and actor as numbers, for web/network.mjs)",
        args.out.display(),
        card.game
    );
    Ok(())
}
