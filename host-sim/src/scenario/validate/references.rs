//! `[leader]` and `velocity_reference`: the maneuvers (S11, S12).

use super::agents::lookup;
use super::checker::Checker;
use crate::model::LeaderModel;
use crate::scenario::error::ErrorKind::{InvalidValue, NonPositiveGain};
use crate::scenario::ScenarioFile;
use std::collections::HashMap;

/// Checks the leader edge; returns it if its agents resolved.
pub(super) fn leader(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
    index: &HashMap<String, usize>,
) -> Option<LeaderModel> {
    match &s.leader {
        None => None,
        Some(l) => {
            let a = lookup(c, index, "leader.agents", &l.agents[0]);
            let b = lookup(c, index, "leader.agents", &l.agents[1]);
            if l.agents[0] == l.agents[1] {
                c.err(
                    InvalidValue,
                    "leader.agents",
                    "the two leaders must be different agents",
                );
            }
            c.positive(NonPositiveGain, "leader.stiffness", l.stiffness);
            for x in l.damping.pair() {
                c.non_negative(NonPositiveGain, "leader.damping", x);
            }
            let displacement = c.schedule("leader.displacement", &l.displacement);
            match (a, b) {
                (Some(a), Some(b)) => Some(LeaderModel {
                    a,
                    b,
                    stiffness: l.stiffness,
                    damping: l.damping.pair(),
                    displacement,
                    orientation: l.orientation,
                }),
                _ => None,
            }
        }
    }
}
