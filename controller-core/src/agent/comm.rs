//! Communication of one agent: what it broadcasts ([`Agent::frames`]) and how it takes in
//! its neighbours' broadcasts ([`Agent::receive`], [`Agent::receive_direct`]). The frame
//! layout is [`crate::wire`]'s.

use super::state::{AngleState, Remote, Side};
use super::{pick, Agent};
use crate::config::AgentId;
use crate::wire::auth::{self, Counter};
use crate::wire::{check_mode, quant, FrameError, Integrity, RawAngle};
// The simulator's entry points (feature `sim`).
use crate::{law, Real, Vec2};
#[cfg(any(feature = "sim", test))]
use {super::finite_vec, crate::config::EstimatorMode, crate::wire::CrcCheck};

/// `auth`: an agent whose broadcasts fill every frame (no room for the counter
/// extension) adds a sync frame (velocity and counter extension, no items) to the first
/// and then every `SYNC_EVERY`-th of them, so that a receiver that boots, or missed
/// more than 2¹⁵ of its frames, learns its counter (see [`crate::wire::auth`]).
pub const SYNC_EVERY: u8 = 8;

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// `auth`: sets this boot's epoch: the next frame's counter is `epoch · 2³²` (see
    /// [`crate::wire::auth`]). Call it once after [`Agent::new`], before the first
    /// [`Agent::frames`], with a value larger than at any earlier boot of this agent (the
    /// firmware keeps it in non-volatile memory and increments it at every boot):
    /// receivers reject every counter not larger than the last one they accepted, so an
    /// agent that reuses an epoch is not heard until its counter passes its old one.
    pub fn set_boot_epoch(&mut self, epoch: u32) {
        self.counter = [epoch, 0];
        self.sync_countdown = 0;
    }

    /// The full counter the next frame will carry (see [`crate::wire::auth`]).
    pub fn next_counter(&self) -> Counter {
        auth::load(self.counter)
    }

    /// Encodes this tick's broadcast into frames of at most 60 bytes and passes each to
    /// `send`; returns the number of frames. The broadcast is the agent's velocity and,
    /// for every controlled angle it is the apex of and computed when it last sensed,
    /// what the angle's far vertices need (see [`crate::wire`]). Sends nothing (and
    /// returns 0) on the steps that [`crate::AgentConfig::comm_every`] skips.
    ///
    /// `auth`: every frame carries the next counter; a broadcast of full frames only is
    /// followed by a sync frame now and then (every `SYNC_EVERY` frames); after `2³² − 1` frames
    /// in one boot epoch the agent sends nothing more (a counter is never reused).
    pub fn frames(&mut self, send: impl FnMut(&[u8])) -> usize {
        self.encode_frames(send)
    }

    /// The most frames [`Agent::frames`] sends in one tick, in any integrity mode: the
    /// items of at most `MT` angles of which this agent is the apex (one per triangle),
    /// as few per frame as `auth` holds ([`crate::wire::MIN_ANGLES_PER_FRAME`]), plus an
    /// `auth` sync frame after a full last frame. For buffers sized once (simulators).
    pub const MAX_FRAMES_PER_TICK: usize = MT.div_ceil(crate::wire::MIN_ANGLES_PER_FRAME) + 1;

    /// [`Agent::frames`], each frame with its [`CrcCheck`] (`crc16` integrity; `None`
    /// otherwise), known without computing the CRC again since this agent has just written
    /// it: for simulators that hand each broadcast to [`Agent::receive_checked`] of every
    /// receiver. Feature `sim` only (not built for the firmware).
    #[cfg(any(feature = "sim", test))]
    pub fn frames_checked(&mut self, mut send: impl FnMut(&[u8], Option<CrcCheck>)) -> usize {
        let crc16 = matches!(self.config.integrity, Integrity::Crc16);
        self.encode_frames(|bytes| send(bytes, crc16.then(|| CrcCheck::written(bytes)).flatten()))
    }

    /// [`Agent::frames`]: this tick's broadcast, each frame passed to `send`.
    fn encode_frames(&mut self, mut send: impl FnMut(&[u8])) -> usize {
        if !self.comm_due {
            return 0;
        }
        let auth = matches!(self.config.integrity, Integrity::Auth(_));
        // `auth`: frame number 2³² − 1 is never used, so the counter stays in its epoch.
        let usable = |c: Counter| !auth || c as u32 != u32::MAX;
        let mut counter = auth::load(self.counter);
        if !usable(counter) {
            return 0;
        }
        let (id, mode) = (self.config.id, self.mode);
        let velocity = [self.velocity.x.as_f32(), self.velocity.y.as_f32()];
        let mut count = 0;
        let (writer, angles) = (&mut self.writer, &self.angles);
        writer.start_counted(mode, id, counter, velocity);
        for a in angles.as_slice().as_flattened() {
            let Some((gamma, sigma, range)) = sent_angle(a) else {
                continue;
            };
            let q = |x: T| quant::encode(x.as_f32()).0;
            let code = [q(gamma), unit_code(q(sigma)), q(range[0]), q(range[1])];
            if !writer.push_angle(a.far, code) {
                send(writer.finish());
                count += 1;
                counter = counter.wrapping_add(1);
                if !usable(counter) {
                    self.counter = auth::store(counter);
                    return count;
                }
                writer.start_counted(mode, id, counter, velocity);
                // One item always fits in an empty frame.
                let _ = writer.push_angle(a.far, code);
            }
        }
        // Frames fill up in order: a full last frame means no frame had room for the
        // counter extension.
        let full = writer.angles() == self.config.integrity.max_angles();
        send(writer.finish());
        count += 1;
        counter = counter.wrapping_add(1);
        if auth && full {
            if self.sync_countdown == 0 && usable(counter) {
                writer.start_counted(mode, id, counter, velocity);
                send(writer.finish());
                count += 1;
                counter = counter.wrapping_add(1);
                self.sync_countdown = SYNC_EVERY - 1;
            } else {
                self.sync_countdown = self.sync_countdown.saturating_sub(1);
            }
        }
        self.counter = auth::store(counter);
        count
    }

    /// Checks and applies one received frame. Rejected frames change nothing but the
    /// counters. With `crc16` and `link` integrity, a neighbour that was stale may
    /// restart its sequence numbers; with `auth`, a frame is applied only if its tag
    /// verifies and its counter is larger than the sender's last accepted one (see
    /// [`crate::wire::auth`]; a rebooted neighbour is heard again from its first frame
    /// with the counter extension of its new, larger boot epoch).
    pub fn receive(&mut self, bytes: &[u8]) -> Result<(), FrameError> {
        let result = self.receive_inner(bytes);
        match result {
            Ok(()) => self.stats.accepted = self.stats.accepted.saturating_add(1),
            Err(_) => self.stats.record(&result),
        }
        result
    }

    /// [`Agent::receive`] of `bytes` whose CRC was checked once for every receiver:
    /// `check` is [`CrcCheck::of`] these same bytes (or `None`). The same result and
    /// counters as `receive`, without computing the CRC again; for simulators that hand
    /// one broadcast to many agents. As a guard, a check whose length or trailer differs
    /// from `bytes` is ignored (the CRC is then computed). Feature `sim` only (not built
    /// for the firmware).
    #[cfg(any(feature = "sim", test))]
    pub fn receive_checked(
        &mut self,
        bytes: &[u8],
        check: Option<CrcCheck>,
    ) -> Result<(), FrameError> {
        let crc_ok = check.and_then(|c| c.result_for(bytes));
        let result = match (self.config.integrity, crc_ok) {
            (Integrity::Crc16, Some(ok)) => self.receive_in(bytes, Integrity::Crc16, Some(ok)),
            _ => self.receive_inner(bytes),
        };
        self.stats.record(&result);
        result
    }

    /// [`Agent::receive`] without the counting: one copy of [`Agent::receive_in`] for
    /// `auth` and one for `crc16`/`link`, so that the integrity mode is tested once per
    /// frame and the `crc16`/`link` path carries none of the `auth` path's work.
    fn receive_inner(&mut self, bytes: &[u8]) -> Result<(), FrameError> {
        match self.config.integrity {
            Integrity::Auth(key) => self.receive_in(bytes, Integrity::Auth(key), None),
            Integrity::Crc16 => self.receive_in(bytes, Integrity::Crc16, None),
            Integrity::Link => self.receive_in(bytes, Integrity::Link, None),
        }
    }

    /// Checks and applies one frame for a receiver with `integrity` (its configured mode,
    /// a constant where it is inlined); `crc_ok`: the CRC check's result if known.
    #[inline(always)]
    fn receive_in(
        &mut self,
        bytes: &[u8],
        integrity: Integrity,
        crc_ok: Option<bool>,
    ) -> Result<(), FrameError> {
        let frame = check_mode(bytes, integrity, self.mode, crc_ok)?;
        let sender = frame.header.sender;
        if sender == self.config.id {
            return Err(FrameError::OwnFrame);
        }
        let slot = self
            .sender_slot(sender)
            .ok_or(FrameError::UnknownSender(sender))?;
        // The next frame is probably from the next slot (wrapping; a slot number that
        // does not fit only makes the next look-up search).
        self.next_slot = u8::try_from(slot + 1).unwrap_or(0);
        let timeout = self.config.limits.neighbour_timeout;
        let n = self
            .neighbours
            .get(slot)
            .ok_or(FrameError::UnknownSender(sender))?;
        let seq = frame.header.seq;
        let accepted_counter = if let Integrity::Auth(key) = &integrity {
            // The replay check first (cheap), then the tag, with the counter as carried
            // or as reconstructed from the last accepted one.
            let last = n.last_counter.map(auth::load);
            let counter = match (frame.carried_counter(), last) {
                (Some(c), _) => c,
                (None, Some(last)) => auth::reconstruct(last, seq),
                (None, None) => return Err(FrameError::Unsynced(sender)),
            };
            if last.is_some_and(|last| counter <= last) {
                return Err(FrameError::Replayed { sender, counter });
            }
            frame.verify_tag(key, counter)?;
            Some(auth::store(counter))
        } else {
            if let Some(last) = n.last_seq {
                // Serial-number arithmetic: newer means ahead by 1..=32767. A neighbour
                // not heard within the timeout may have restarted.
                let ahead = seq.wrapping_sub(last);
                if (ahead == 0 || ahead >= 0x8000) && n.age <= timeout {
                    return Err(FrameError::StaleSequence { sender, seq });
                }
            }
            None
        };
        // The whole frame is valid before anything is applied. With estimators, the
        // distances are estimates: at least r_min (as rounded: rounding is monotone).
        frame.validate(self.range_min_code)?;
        let [vx, vy] = frame.velocity;
        if let Some(n) = self.neighbours.get_mut(slot) {
            n.last_seq = Some(seq);
            if accepted_counter.is_some() {
                n.last_counter = accepted_counter;
            }
            n.age = T::zero();
            // The velocity item (as `apply` stores it, without a second look-up).
            n.velocity = Vec2::new(T::of_f32(vx), T::of_f32(vy));
        }
        self.oldest = None;
        let me = self.config.id;
        for RawAngle { far, codes } in frame.raw_items() {
            // Only the items for angles of which this agent is a far vertex. Validated:
            // finite.
            let v = |c: u16| T::of_f32(quant::from_code(c));
            let [g, s, r0, r1] = codes;
            if let Some((k, other)) = far_role(far, me) {
                self.apply_angle(slot, other, v(g), v(s), v(pick(&[r0, r1], k)));
            }
        }
        Ok(())
    }

    /// Takes a neighbour's broadcast directly, without the wire (no rounding, no sequence
    /// numbers): for in-process simulation and tests. The broadcast passes the checks
    /// [`Agent::receive`] applies to a frame's values before anything is applied: a
    /// finite velocity, and for every angle sent, distinct far vertices
    /// ([`FrameError::Malformed`]), a finite `γ` and `σ` and distances that are finite,
    /// positive and (with estimators) at least `r_min` ([`FrameError::InvalidValue`]).
    /// (`|σ| ≤ 1` is not checked: the wire rounds `σ` into it, a direct value may exceed
    /// it by a rounding.) Feature `sim` only (not built for the firmware).
    #[cfg(any(feature = "sim", test))]
    pub fn receive_direct(&mut self, from: &Self) -> Result<(), FrameError> {
        let sender = from.id();
        let slot = self.slot(sender).ok_or(FrameError::UnknownSender(sender))?;
        self.check_direct(from)?;
        if let Some(n) = self.neighbours.get_mut(slot) {
            n.age = T::zero();
            n.velocity = from.velocity;
        }
        self.oldest = None;
        let me = self.config.id;
        for a in from.angles.iter().flatten() {
            if let (Some((gamma, sigma, range)), Some((k, other))) =
                (sent_angle(a), far_role(a.far, me))
            {
                self.apply_angle(slot, other, gamma, sigma, pick(&range, k));
            }
        }
        Ok(())
    }

    /// The value checks of [`Agent::receive_direct`] (those of `FrameView::validate` on
    /// full-precision values).
    #[cfg(any(feature = "sim", test))]
    fn check_direct(&self, from: &Self) -> Result<(), FrameError> {
        if !finite_vec(&from.velocity) {
            return Err(FrameError::InvalidValue);
        }
        let r_min = match self.config.estimator {
            EstimatorMode::Measured => T::zero(),
            EstimatorMode::Shared | EstimatorMode::PerAgent => self.config.min_estimate,
        };
        let distance = |r: T| r.finite() && r > T::zero() && r >= r_min;
        for a in from.angles.iter().flatten() {
            if let Some((gamma, sigma, range)) = sent_angle(a) {
                if a.far[0] == a.far[1] {
                    return Err(FrameError::Malformed);
                }
                if !(gamma.finite() && sigma.finite() && distance(range[0]) && distance(range[1])) {
                    return Err(FrameError::InvalidValue);
                }
            }
        }
        Ok(())
    }

    /// Stores what the apex in neighbour `slot` sent of its angle `(apex; me, other)`:
    /// `γ`, `σ` and its distance to this agent `r`.
    #[inline]
    fn apply_angle(&mut self, slot: usize, other: AgentId, gamma: T, sigma: T, range: T) {
        let Some(n) = self.neighbours.get(slot) else {
            return;
        };
        let v_ref = self.velocity;
        // At most one angle per triangle has this apex and this agent as a far vertex;
        // the other far vertex tells them apart.
        for e in n.apex_of.iter().filter(|e| e.other == other) {
            let flat = usize::from(e.flat);
            let a = self
                .angles
                .get_mut(flat / 2)
                .and_then(|t| t.get_mut(flat % 2));
            if let Some(AngleState {
                side: Side::Far { k, remote, age },
                ..
            }) = a
            {
                *remote = Remote {
                    gamma,
                    // S6: this far vertex's sign, once here rather than every step.
                    sigma: law::far_sigma(sigma, *k),
                    range,
                    v_ref,
                };
                *age = T::zero();
            }
        }
    }
}

/// Which far vertex of an angle `(sender; far[0], far[1])` the agent `me` is, and the
/// other one: `(k, far[1 − k])`; `None` if it is neither. The one place where a received
/// angle is matched to its receiver, for [`Agent::receive`] and [`Agent::receive_direct`].
#[inline]
fn far_role(far: [AgentId; 2], me: AgentId) -> Option<(usize, AgentId)> {
    if far[0] == me {
        Some((0, far[1]))
    } else if far[1] == me {
        Some((1, far[0]))
    } else {
        None
    }
}

/// The binary16 code `c` with its magnitude limited to 1: `σ = s_nv × s_nw` of
/// bearings that are unit only within the tolerance can exceed 1 by a rounding, which
/// receivers refuse (`|σ| ≤ 1`, see [`crate::wire`]). Found by the fuzz target.
#[inline(always)]
fn unit_code(c: u16) -> u16 {
    const ONE: u16 = 0x3C00;
    if c & 0x7FFF > ONE {
        (c & 0x8000) | ONE
    } else {
        c
    }
}

/// What an apex sends of angle `a` (`γ`, `σ`, `[r_v, r_w]`): the values of its last
/// sense, if it computed them (they are then finite: see `sensing::apex_part`).
#[inline]
#[allow(clippy::type_complexity)]
fn sent_angle<T: Real>(a: &AngleState<T>) -> Option<(T, T, [T; 2])> {
    match &a.side {
        Side::Apex { part, fault: None } => Some((part.gamma, part.sigma, part.range)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::unit_code;
    use crate::agent::test_support::one_triangle;
    use crate::wire::auth::{self, Counter};
    use crate::wire::{FrameError, Integrity, SwarmKey};
    use crate::{Agent, Vec2};

    /// `receive_direct` refuses what `receive` refuses, before applying anything: a
    /// non-finite velocity (it took any broadcast as it was).
    #[test]
    fn receive_direct_applies_the_value_checks_of_receive() {
        let mut me = Agent::<f64, 1, 2>::new(one_triangle(2, [1, 2], 0.5)).unwrap();
        let mut from = Agent::<f64, 1, 2>::new(one_triangle(1, [1, 2], 0.5)).unwrap();
        from.velocity = Vec2::new(1.0, 2.0);
        assert_eq!(me.receive_direct(&from), Ok(()));
        let slot = me.slot(1).unwrap();
        assert_eq!(me.neighbours[slot].velocity, Vec2::new(1.0, 2.0));
        from.velocity = Vec2::new(f64::NAN, 0.0);
        assert_eq!(me.receive_direct(&from), Err(FrameError::InvalidValue));
        assert_eq!(me.neighbours[slot].velocity, Vec2::new(1.0, 2.0));
    }

    /// An `auth` agent `id` in the triangle (1, 2, 3).
    fn auth_agent(id: u8) -> Agent<f32, 1, 2> {
        let mut c = one_triangle(id, [1, 2], 0.5);
        c.integrity = Integrity::Auth(SwarmKey::new([7; 16]));
        Agent::new(c).expect("valid configuration")
    }

    /// Frames of one call of `frames`.
    fn broadcast(a: &mut Agent<f32, 1, 2>) -> std::vec::Vec<std::vec::Vec<u8>> {
        let mut out = std::vec::Vec::new();
        a.frames(|f| out.push(f.to_vec()));
        out
    }

    /// A boot epoch's last counters: frames up to number 2³² − 2 go out and are heard;
    /// then the agent is silent (counter 2³² − 1 is never used, the epoch never spills
    /// into the next one) until it starts a new boot epoch, whose frames are heard again.
    #[test]
    fn an_exhausted_boot_epoch_sends_nothing_until_the_next_epoch() {
        let epoch: Counter = 7 << 32;
        let mut sender = auth_agent(1);
        let mut receiver = auth_agent(2);
        sender.counter = auth::store(epoch + u64::from(u32::MAX) - 2);
        for last in [2, 1] {
            let frames = broadcast(&mut sender);
            assert_eq!(frames.len(), 1);
            receiver.receive(&frames[0]).expect("authentic and newer");
            assert_eq!(
                sender.next_counter(),
                epoch + u64::from(u32::MAX) - last + 1
            );
        }
        for _ in 0..3 {
            assert!(broadcast(&mut sender).is_empty(), "a counter was reused");
            assert_eq!(sender.next_counter(), epoch + u64::from(u32::MAX));
        }
        sender.set_boot_epoch(8);
        let frames = broadcast(&mut sender);
        assert_eq!(frames.len(), 1);
        receiver
            .receive(&frames[0])
            .expect("the new epoch is newer");
        assert_eq!(sender.next_counter(), (8 << 32) + 1);
    }

    #[test]
    fn sigma_codes_are_limited_to_one() {
        // binary16: 0x3C00 = 1, 0x3C01 = 1 + 2⁻¹⁰, 0xBC01 = −(1 + 2⁻¹⁰), 0x3BFF < 1.
        assert_eq!(unit_code(0x3C01), 0x3C00);
        assert_eq!(unit_code(0xBC01), 0xBC00);
        assert_eq!(unit_code(0x3C00), 0x3C00);
        assert_eq!(unit_code(0xBC00), 0xBC00);
        assert_eq!(unit_code(0x3BFF), 0x3BFF);
        assert_eq!(unit_code(0x8001), 0x8001);
        assert_eq!(unit_code(0), 0);
    }
}
