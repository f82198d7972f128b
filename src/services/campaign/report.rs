//! What a campaign says of itself: the Markdown page and the charts of its record, the share of
//! players who finish it, and where the panel's difficulty steps down along it.

use super::{Campaign, CampaignLevel};
use crate::services::chart::{LineChart, Series};

impl Campaign {
    /// The share of the population that finishes the campaign.
    pub fn finishers(&self) -> f64 {
        self.levels
            .last()
            .map_or(1.0, |l| l.players.reach - l.players.quit)
    }

    /// The campaign as a Markdown page: what was asked, a table per level, the funnel.
    pub fn to_markdown(&self) -> String {
        let p = &self.population;
        let mut page = format!(
            "# Campaign: {} {} levels, seed {}\n\n\
             Ramp asked for `{}` (success of `{}`, {} runs per level){}. Population: θ ~ \
             Normal({:+.2}, {:.2}) logits ({}), retries after a failure with chance {:.2}; \
             {:.1}% of players finish the campaign.\n\n\
             | level | file | asked | measured (95% CI) | λ | b (95% CI) | reach | quit here | attempts per success |\n\
             |---|---|---|---|---|---|---|---|---|\n",
            self.levels.len(),
            self.game,
            self.seed,
            self.ramp,
            self.judge,
            self.trials,
            self.pacing.as_ref().map_or(String::new(), |c| format!(
                ", each level paced by `{c}` moved as a whole"
            )) + &self.profile.as_ref().map_or(String::new(), |p| format!(
                ", made for profile `{}`",
                p.name
            )),
            p.theta_mean,
            p.theta_sd,
            self.population_from,
            p.retry,
            100.0 * self.finishers(),
        );
        for (k, l) in self.levels.iter().enumerate() {
            let aux = match (l.aux, &l.aux_curve) {
                (Some(aux), _) => format!("{aux:+.2}"),
                (None, Some(curve)) => format!("`{curve}`"),
                (None, None) => String::new(),
            };
            page += &format!(
                "| {} | {} | {:.2} | {:.2} ({:.2}–{:.2}) | {aux} | {:+.2} ({:+.2} to {:+.2}) | {:.3} | {:.3} | {:.2} |\n",
                k + 1,
                l.file,
                l.asked,
                l.measured,
                l.ci95[0],
                l.ci95[1],
                l.b,
                l.b_ci95[0],
                l.b_ci95[1],
                l.players.reach,
                l.players.quit,
                l.players.attempts_per_success,
            );
        }
        let thetas: Vec<String> = self
            .judges_theta
            .iter()
            .map(|j| format!("{} {:+.2}", j.judge, j.theta))
            .collect();
        page += &format!("\nJudges' ability θ (logits): {}.\n", thetas.join(", "));
        page += &format!("\n{}.\n", self.b_trend());
        if !self.checks.is_empty() {
            let checks: Vec<String> = self.checks.iter().map(|c| format!("`{c}`")).collect();
            page += &format!("\nChecks every level must pass: {}.\n", checks.join(", "));
        }
        page
    }

    /// The campaign's charts, one above the other: success asked and measured with the share
    /// of players who reach each level; and b per level with its interval.
    pub fn charts(&self) -> Vec<LineChart> {
        let per_level = |f: &dyn Fn(&CampaignLevel) -> f64| -> Vec<(f64, f64)> {
            self.levels
                .iter()
                .enumerate()
                .map(|(k, l)| ((k + 1) as f64, f(l)))
                .collect()
        };
        let series = |name: &str, f: &dyn Fn(&CampaignLevel) -> f64| Series {
            name: name.into(),
            points: per_level(f),
        };
        vec![
            LineChart {
                title: format!(
                    "{} campaign: success of {} and players who reach each level",
                    self.game, self.judge
                ),
                x_label: "level".into(),
                y_label: "share".into(),
                series: vec![
                    series("asked", &|l| l.asked),
                    series("measured", &|l| l.measured),
                    series("players reaching", &|l| l.players.reach),
                ],
                y_range: Some((0.0, 1.0)),
            },
            LineChart {
                title: "difficulty b on the panel's scale (95% interval)".into(),
                x_label: "level".into(),
                y_label: "b (logits)".into(),
                series: vec![
                    series("b", &|l| l.b),
                    series("low", &|l| l.b_ci95[0]),
                    series("high", &|l| l.b_ci95[1]),
                ],
                y_range: None,
            },
        ]
    }

    /// Whether b rises along the campaign, in words: `b rises level to level within its
    /// intervals`, or where it steps down.
    pub fn b_trend(&self) -> String {
        match self.steps_down()[..] {
            [] => "b rises level to level within its intervals".into(),
            ref down => format!(
                "b steps down beyond its intervals at level {}",
                down.iter()
                    .map(|k| k.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    }

    /// The levels (numbered from 1) whose b falls below the one before it beyond both
    /// intervals: where the campaign steps down for the panel.
    pub fn steps_down(&self) -> Vec<usize> {
        self.levels
            .windows(2)
            .enumerate()
            .filter(|(_, pair)| pair[1].b_ci95[1] < pair[0].b_ci95[0])
            .map(|(k, _)| k + 2)
            .collect()
    }
}
