//! The designer's side of the worker's answers: each [`Response`] updates the state it is
//! for and may ask for more work (a new level's trials, a regeneration after a load).

use super::*;

impl App {
    pub(super) fn response(&mut self, response: Response) -> Vec<Effect> {
        match response {
            Response::Level { id, result } => self.level_arrived(id, result),
            Response::Trial { id, result } => {
                if let Some(trials) = self.trials.as_mut().filter(|t| t.id == id) {
                    trials.results.push(result);
                }
                Vec::new()
            }
            Response::TrialsDone { id, stats } => {
                if let Some(trials) = self.trials.as_mut().filter(|t| t.id == id) {
                    trials.stats = Some(*stats);
                }
                Vec::new()
            }
            Response::StandIn { id, why } => {
                if let Some(trials) = self.trials.as_mut().filter(|t| t.id == id) {
                    trials.stand_in = Some(why.clone());
                    self.say(why);
                }
                Vec::new()
            }
            Response::TrialsFailed { id, problem } => {
                if let Some(trials) = self.trials.as_mut().filter(|t| t.id == id) {
                    trials.error = Some(problem.clone());
                    self.complain(format!("the trials stopped: {problem}"));
                }
                Vec::new()
            }
            Response::Recorded { id, result } => {
                self.recorded(id, result);
                Vec::new()
            }
            Response::SweepPoint { id, index, point } => {
                self.sweep_point(id, index, point);
                Vec::new()
            }
            Response::Exported(outcome) => {
                self.exported(outcome);
                Vec::new()
            }
            Response::Judged(result) => match result {
                Ok(switch) => {
                    self.policies_mut().solver = switch.solver;
                    self.policies_mut().skill = switch.skill;
                    self.say(format!(
                        "judge: {} plays the trials",
                        self.policies().judge().name()
                    ));
                    self.generate()
                }
                Err(problem) => {
                    self.complain(problem);
                    Vec::new()
                }
            },
            Response::Panel { id, update } => {
                self.panel_update(id, update);
                Vec::new()
            }
            Response::Campaign(result) => {
                self.campaign_opened(result);
                Vec::new()
            }
            Response::Profile(result) => self.profile_loaded(result),
            Response::Loaded(result) => match result {
                Ok(info) => self.loaded(*info),
                Err(problem) => {
                    self.complain(problem);
                    Vec::new()
                }
            },
        }
    }

    /// The requested level (or why there is none) arrives; an older request's is dropped.
    fn level_arrived(&mut self, id: u64, result: Result<Arc<Level>, String>) -> Vec<Effect> {
        if self.loading != (Loading::Generating { id }) {
            return Vec::new();
        }
        self.loading = Loading::Idle;
        match result {
            Ok(level) => {
                self.generation_error = None;
                self.selected = self.selected.filter(|&i| i < level.piece_count());
                // With a success target or a wish list the slider shows the λ the search found.
                let searched = self.ask.success().is_some() || self.want().is_some();
                if let (true, Some(aux)) = (searched, level.aux) {
                    self.aux = aux;
                }
                self.level = Some(level);
                let mut effects = self.start_trials();
                effects.extend(self.judge_if_shown());
                effects
            }
            Err(problem) => {
                self.generation_error = Some(problem.clone());
                self.level = None;
                self.trials = None;
                self.complain(problem);
                Vec::new()
            }
        }
    }

    /// The replay asked for last arrives (an older one is dropped).
    fn recorded(&mut self, id: u64, result: Result<Box<Recording>, String>) {
        let Some((_, seed)) = self.recording.filter(|&(wanted, _)| wanted == id) else {
            return;
        };
        self.recording = None;
        match result {
            Ok(recording) => {
                self.say(format!(
                    "replay: {} after {} steps",
                    recording.result.outcome.describe(),
                    recording.result.steps
                ));
                self.replay = Some(Replay {
                    seed,
                    recording: *recording,
                    frame: 0,
                });
            }
            Err(problem) => self.complain(problem),
        }
    }

    fn exported(&mut self, outcome: ExportOutcome) {
        match outcome {
            ExportOutcome::Written(paths) => self.say(format!(
                "exported {}",
                paths
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
            ExportOutcome::WouldOverwrite(paths) => {
                self.overlay = Overlay::ConfirmOverwrite { paths };
            }
            ExportOutcome::Failed(problem) => self.complain(problem),
        }
    }

    /// Policies loaded: they take their roles and the level is generated again.
    fn loaded(&mut self, info: LoadedInfo) -> Vec<Effect> {
        self.say(format!(
            "loaded {}",
            [&info.generator, &info.solver]
                .into_iter()
                .flatten()
                .map(|p| p.path.display().to_string())
                .collect::<Vec<_>>()
                .join(" and ")
        ));
        if info.generator.is_some() {
            self.policies_mut().generator = info.generator;
        }
        if info.solver.is_some() {
            self.policies_mut().solver = info.solver;
        }
        self.generate()
    }
}
