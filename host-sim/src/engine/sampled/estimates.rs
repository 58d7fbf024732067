//! The estimates of [`super::SampledSim`]'s controllers as the diagnostics read them:
//! every controller's values in one array, copied from the controllers when viewed.

use crate::engine::controller::AgentController;
use crate::engine::error::SetupError;
use crate::model::{resolve_estimates, EstimateInfo, Model};

/// Every controller's estimates, in agent order.
pub(super) struct Estimates {
    /// The values: agent `i`'s at `start[i]..start[i + 1]`.
    pub(super) values: Vec<f64>,
    /// Where each agent's values start (one entry more than the agents).
    pub(super) start: Vec<usize>,
    /// `values` holds every controller's current values: the tick copied them (an
    /// estimate changes only at a tick), so [`crate::engine::Engine::view`] need not.
    pub(super) fresh: bool,
    /// [`crate::engine::Engine::view`] was called: from then on each agent's tick copies
    /// its estimates while its state is in cache (a run's diagnostics view every control
    /// instant; the benchmark's `SampledSim::advance_ticks` never views, and copies
    /// nothing).
    pub(super) viewed: bool,
    /// What each value is.
    pub(super) info: Vec<EstimateInfo>,
}

impl Estimates {
    /// The estimates of `controllers` (one per agent of `model`, in agent order; each must
    /// carry its agent's id), at the model's initial estimate.
    pub(super) fn new(
        model: &Model,
        controllers: &[Box<dyn AgentController>],
    ) -> Result<Self, SetupError> {
        let mut info = Vec::new();
        let mut start = Vec::with_capacity(controllers.len() + 1);
        for (i, c) in controllers.iter().enumerate() {
            if c.id() != model.agents[i].id {
                return Err(SetupError::ControllerId {
                    index: i,
                    id: c.id(),
                    expected: model.agents[i].id,
                });
            }
            start.push(info.len());
            info.extend(resolve_estimates(model, i, &c.estimate_layout())?);
        }
        start.push(info.len());
        Ok(Self {
            values: vec![model.initial_estimate; info.len()],
            start,
            fresh: false,
            viewed: false,
            info,
        })
    }

    /// Copies agent `i`'s current estimates from `controller` into its slots of `values`
    /// (`start[i]..start[i + 1]`).
    pub(super) fn read_of(
        controller: &dyn AgentController,
        values: &mut [f64],
        start: &[usize],
        i: usize,
    ) {
        let (a, b) = (start[i], start[i + 1]);
        if let Some(slot) = values.get_mut(a..b) {
            controller.read_estimates(slot);
        }
    }

    /// Copies every controller's estimates unless the last tick did.
    pub(super) fn refresh(&mut self, controllers: &[Box<dyn AgentController>]) {
        if !self.fresh {
            // The first view, or after a tick that did not copy them (about once a run:
            // from now on every tick copies them).
            for (i, c) in controllers.iter().enumerate() {
                Self::read_of(&**c, &mut self.values, &self.start, i);
            }
            self.fresh = true;
        }
    }
}
