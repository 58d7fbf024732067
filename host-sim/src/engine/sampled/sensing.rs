//! The sensing stage of [`super::SampledSim`]: what each agent measures at its tick
//! ([`Scene::measure`]): its bearings (the omnidirectional ideal sensor's own loops, or a
//! [`BearingSensor`]), its own velocity and a leader's partner offset, drawn from its own
//! stream of the tick.

use crate::engine::plant::Plant;
use crate::engine::sensors::{
    bearing_sensor, offset_with, quiet_bearing, velocity_with, BearingKind, BearingSensor, Sensors,
    Sight, World,
};
use crate::model::graph::Adjacency;
use crate::model::{BearingRate, Estimator, Model};
use ph_formation_core::{BearingMeasurement, Vec2};

/// How a tick measures: exact bearing rates, ranges, sensors that draw nothing.
#[derive(Clone, Copy, Debug)]
pub(super) struct MeasureMode {
    exact: bool,
    ranged: bool,
    quiet: bool,
}

/// What a run's agents measure with: the sensors, the bearing sensor (`None`: the
/// omnidirectional ideal one, [`Scene::measure`]'s own loops), every agent's wire id (a
/// bearing's tag) and leader partner.
pub(super) struct Senses {
    pub(super) sensors: Sensors,
    pub(super) bearing: Option<Box<dyn BearingSensor>>,
    ids: Vec<u8>,
    partner: Vec<Option<usize>>,
}

impl Senses {
    /// The sensors of `model`'s run with control period `period` (s).
    pub(super) fn new(model: &Model, period: f64) -> Self {
        Self {
            sensors: Sensors::new(&model.sensors, model.seed),
            bearing: bearing_sensor(model, period),
            ids: model.agents.iter().map(|a| a.id).collect(),
            partner: model.partners(),
        }
    }

    /// The bearing sensor takes in the true state of this control tick (`headings`: each
    /// agent's true heading), before any agent is measured.
    pub(super) fn prepare(&mut self, plant: &dyn Plant, headings: &[f64]) {
        if let Some(sensor) = &mut self.bearing {
            sensor.prepare(&World {
                q: plant.q(),
                v: plant.v(),
                headings,
            });
        }
    }

    /// Whether the bearing sensor sends packets of its own over the radio
    /// ([`BearingSensor::uses_radio`]).
    pub(super) fn uses_radio(&self) -> bool {
        self.bearing.as_ref().is_some_and(|s| s.uses_radio())
    }
}

/// What one tick's measurements read: the state, who sees whom and the sensors.
pub(super) struct Scene<'a> {
    graph: &'a Adjacency,
    q: &'a [Vec2<f64>],
    v: &'a [Vec2<f64>],
    /// Each agent's true heading (rad).
    headings: &'a [f64],
    senses: &'a Senses,
    mode: MeasureMode,
}

impl<'a> Scene<'a> {
    /// The scene of a simulator's parts (taken one by one, so that the caller may write
    /// its other fields meanwhile).
    pub(super) fn of(
        model: &'a Model,
        plant: &'a dyn Plant,
        senses: &'a Senses,
        headings: &'a [f64],
    ) -> Self {
        let ranged = model.estimator == Estimator::Measured;
        Self {
            graph: &model.graph.triangle,
            q: plant.q(),
            v: plant.v(),
            headings,
            senses,
            mode: MeasureMode {
                exact: model.sensors.bearing_rate == BearingRate::Exact,
                ranged,
                quiet: !senses.sensors.draws(ranged),
            },
        }
    }

    /// Agent `i`'s measurements at its tick `tick`: its bearings in graph order (to
    /// `push`), then its own velocity and (a leader) its partner offset, drawn in that
    /// order from its stream of the tick ([`Sensors::stream`]); with sensors that draw nothing
    /// ([`MeasureMode::quiet`]) the same values from the state alone, without a stream.
    /// With a bearing sensor, the bearings are its ([`Self::measure_through`]).
    #[inline]
    pub(super) fn measure(
        &self,
        i: usize,
        tick: u64,
        mut push: impl FnMut(BearingMeasurement<f64>),
    ) -> (Vec2<f64>, Option<Vec2<f64>>) {
        if let Some(sensor) = self.senses.bearing.as_deref() {
            return self.measure_through(sensor, i, tick, push);
        }
        let (q, v, m) = (self.q, self.v, self.mode);
        let Senses {
            sensors,
            ids,
            partner,
            bearing: _,
        } = self.senses;
        let model = sensors.model();
        let partner = partner[i];
        let sight = |j: usize| Sight::between(ids, q, v, i, j);
        // Two loops rather than a test per bearing: the quiet one is the common case.
        if m.quiet {
            for &j in self.graph.of(i) {
                if let Some(b) = quiet_bearing(model, &sight(j), m.exact, m.ranged) {
                    push(b);
                }
            }
            let velocity = velocity_with(model, &v[i], [0.0; 2]);
            return (
                velocity,
                partner.map(|p| offset_with(&q[i], &q[p], [0.0; 2])),
            );
        }
        let mut draws = sensors.stream(i, tick);
        for &j in self.graph.of(i) {
            if let Some(b) = draws.bearing(&sight(j), m.exact, m.ranged) {
                push(b);
            }
        }
        let velocity = draws.velocity(&v[i]);
        (velocity, partner.map(|p| draws.offset(&q[i], &q[p])))
    }

    /// [`Self::measure`] with the bearings of `sensor` ([`BearingSensor::bearing`]), then
    /// the velocity and partner offset, all from agent `i`'s stream of this tick.
    #[inline(never)]
    fn measure_through(
        &self,
        sensor: &dyn BearingSensor,
        i: usize,
        tick: u64,
        mut push: impl FnMut(BearingMeasurement<f64>),
    ) -> (Vec2<f64>, Option<Vec2<f64>>) {
        let (q, v, m) = (self.q, self.v, self.mode);
        let s = self.senses;
        let world = World {
            q,
            v,
            headings: self.headings,
        };
        let kind = BearingKind {
            exact_rate: m.exact,
            with_range: m.ranged,
        };
        let mut draws = s.sensors.stream(i, tick);
        for &j in self.graph.of(i) {
            if let Some(b) = sensor.bearing(&world, &s.ids, i, j, kind, &mut draws) {
                push(b);
            }
        }
        let velocity = draws.velocity(&v[i]);
        let offset = s.partner[i].and_then(|p| sensor.partner_offset(&world, i, p, &mut draws));
        (velocity, offset)
    }
}
