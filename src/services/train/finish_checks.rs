//! The finish's own checks of an adversarial run: the pair played aside as it stands, its
//! best-checked Generator kept and, at a Generator phase's cap, brought back.

use super::adversarial_run::AdversarialRun;
use super::own_check;
use super::{BEST_CHECK_GENERATOR, Training};
use crate::services::fsio;
use crate::services::fsio::Overwrite;
use anyhow::Result;
use arlpcg_core::game::generator::GeneratorGame;
use arlpcg_core::level::profile::Profile;
use arlpcg_core::rl::checkpoint;
use arlpcg_core::rl::checkpoint::Role;
use arlpcg_core::seed_ranges::FINISH_CHECK_SEED_BASE;

impl<G: GeneratorGame> AdversarialRun<G> {
    /// The run's profile (none: ours).
    pub(super) fn profile(&self) -> Result<Option<Profile>> {
        self.solver
            .config
            .profile
            .as_ref()
            .map(|record| record.profile(G::GAME))
            .transpose()
            .map_err(|problem| anyhow::anyhow!("the run's profile: {problem}"))
    }

    /// The own check of the pair as it stands, on twice its levels and the finish's own seeds
    /// ([`crate::services::train::config::Finish::own_check_every`]): the policies are written
    /// (as at a pause) and played.
    pub(super) fn finish_check(
        &mut self,
        wall: &dyn Fn() -> f64,
    ) -> Result<Option<own_check::OwnControl>> {
        self.save_policies(wall())?;
        let mut check = self.solver.config.generator.own_check;
        check.levels = check.levels.saturating_mul(2);
        own_check::own_control(
            &self.solver.out,
            G::GAME,
            self.profile()?.as_ref(),
            (check, false),
            FINISH_CHECK_SEED_BASE,
        )
    }

    /// After a finish check that did not pass: its Generator (as `finish_check` just wrote it)
    /// becomes the best-checked one when its check left more slack than any before.
    pub(super) fn keep_if_best_check(&mut self, control: &own_check::OwnControl) -> Result<()> {
        let slack = control.slack(own_check::FINISH_HARD_MARGIN);
        let state = &mut self.envs().state;
        if state.best_check.is_some_and(|best| best >= slack) {
            return Ok(());
        }
        state.best_check = Some(slack);
        let out = &self.solver.out;
        let bytes = fsio::read_limited(
            &out.join("generator.safetensors"),
            checkpoint::MAX_POLICY_BYTES,
            "policy",
        )?;
        fsio::write_atomic(&out.join(BEST_CHECK_GENERATOR), &bytes, Overwrite::Allowed)
    }

    /// A finish's Generator phase that ran to its cap without passing its check ends with the
    /// best-checked Generator: its weights and observation normalizer come back.
    pub(super) fn restore_best_check(&mut self) -> Result<()> {
        let path = self.solver.out.join(BEST_CHECK_GENERATOR);
        let bytes = fsio::read_limited(&path, checkpoint::MAX_POLICY_BYTES, "policy")?;
        let loaded = checkpoint::load_policy(
            &bytes,
            G::GAME,
            Role::Generator,
            arlpcg_core::game::generator::observation_size::<G>(),
        )
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let generator = &mut self.envs().generator;
        for (name, var) in generator.ppo.policy.named_vars() {
            checkpoint::restore_var(&loaded.tensors, &name, &var)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        }
        generator.norm = loaded.card.normalizer;
        Ok(())
    }
}
