//! The `qemu-uart` board: one robot whose sensors, radio and actuator are a
//! host at the other end of a serial line (host-in-the-loop).
//!
//! The host speaks the lock-step protocol of [`ph_formation_core::link`]:
//! postcard messages, one per COBS frame (`0`-delimited):
//!
//! | host → target | target → host |
//! | --- | --- |
//! | `Configure(AgentConfig<f32, 4>)` | `Ready { id, version }` or `Error(Config(code))` |
//! | `Radio(frame)`, any number | (nothing; queued for the next `Step`) |
//! | `Step(LinkStep)` | `Radio(frame)` for each frame to broadcast, `Estimates` (the estimates the agent owns after the step, if any), then `Output(LinkOutput)` |
//! | `Finish` | `Finished { accepted, rejected }` (then the firmware exits 0) |
//!
//! Start-up: QEMU's USART drops the bytes that arrive before the firmware has
//! enabled its receiver, so a host must not send before the target is
//! listening. The target therefore announces itself with one `0` byte (an
//! empty COBS frame) as soon as USART1 is enabled ([`Session::announce`]); a
//! host waits for that byte, then sends `Configure`. Empty frames (a `0`
//! right after a `0`) are ignored in both directions, so a host may also
//! send a `0` first to flush a partial frame.
//!
//! A message that does not decode gets `Error(Malformed)`; `Radio` or `Step`
//! before a successful `Configure` gets `Error(NotConfigured)`. Frames the
//! agent rejects are not reported one by one (a broadcast radio delivers
//! frames of non-neighbours too): `LinkOutput::rejected` counts them.
//!
//! `Step` runs one tick of the same generic [`ControlLoop`] as every other
//! board, over the drivers of this module: the bearing sensor, velocity
//! source and partner offset read the `Step` message, the radio's receive
//! queue holds the `Radio` messages that preceded it and its `send` writes
//! `TargetMsg::Radio` to the line at once, the actuator keeps the force for
//! the `Output`, and the clock counts microseconds: it starts at the first
//! `Step`'s `time` and advances by each `Step`'s `dt` (rounded to 1 µs).
//!
//! The protocol logic ([`Session`]) is generic over a [`SerialPort`];
//! `Usart1` (MCU builds only) is the STM32F4 USART1, polled, sleeping in
//! `wfi` while it waits for a byte.

use heapless::Deque;
use ph_formation_core::link::{
    link_estimates, HostMsg, LinkError, LinkOutput, LinkStep, TargetMsg, LINK_VERSION, MAX_LINK_MSG,
};
use ph_formation_core::wire::{cobs_encode, CobsAccumulator};
use ph_formation_core::{Agent, AgentId};

use crate::app::{Board, ControlLoop, TickReport};
use crate::hal::{
    Actuator, Bearing, BearingSensor, Clock, Radio, Vec2, VelocitySource, MAX_FRAME_LEN,
};

/// Triangles the UART agent can hold.
pub const MT: usize = 4;
/// Neighbours the UART agent can hold.
pub const NB: usize = 8;
/// The agent the host configures.
pub type UartAgent = Agent<f32, MT, NB>;
/// Radio frames queued between two `Step`s (more are dropped and counted).
pub const RADIO_QUEUE: usize = 24;
/// Clock rate of the board (ticks per second): microseconds.
pub const CLOCK_HZ: u32 = 1_000_000;
/// Largest COBS chunk of one host message (before the `0` delimiter).
pub const MAX_COBS_MSG: usize = MAX_LINK_MSG + MAX_LINK_MSG / 254 + 1;

/// A byte-oriented serial line (blocking).
pub trait SerialPort {
    /// Waits for and returns the next received byte.
    fn read_byte(&mut self) -> u8;
    /// Sends `bytes` (waits until each can be written).
    fn write_all(&mut self, bytes: &[u8]);
}

/// What [`Session::poll`] handled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// `Configure`: the agent was built; `Ready` was sent.
    Configured(AgentId),
    /// `Step`: one control tick ran; its frames and `Output` were sent.
    Ticked(TickReport),
    /// `Radio`: a frame was queued for the next tick.
    Queued,
    /// `Finish`: `Finished` was sent; the session is over.
    Finished {
        /// Frames the agent accepted over the run.
        accepted: u32,
        /// Frames the agent rejected over the run.
        rejected: u32,
    },
    /// A message was refused; `Error(e)` was sent.
    Refused(LinkError),
}

/// One queued radio frame.
#[derive(Clone, Copy, Debug)]
struct Frame {
    len: u8,
    bytes: [u8; MAX_FRAME_LEN],
}

/// The host-in-the-loop protocol over a [`SerialPort`].
#[derive(Debug)]
pub struct Session<P: SerialPort> {
    port: P,
    acc: CobsAccumulator<MAX_COBS_MSG>,
    /// Bytes pushed into `acc` since the last delimiter.
    pending: usize,
    msg: [u8; MAX_LINK_MSG],
    control: Option<ControlLoop<MT, NB>>,
    radio: Deque<Frame, RADIO_QUEUE>,
    /// Radio frames dropped because the queue was full.
    pub radio_dropped: u32,
    clock_us: Option<u64>,
}

impl<P: SerialPort> Session<P> {
    /// A session waiting for `Configure`.
    pub fn new(port: P) -> Self {
        Session {
            port,
            acc: CobsAccumulator::new(),
            pending: 0,
            msg: [0; MAX_LINK_MSG],
            control: None,
            radio: Deque::new(),
            radio_dropped: 0,
            clock_us: None,
        }
    }

    /// The control loop, once configured.
    pub fn control(&self) -> Option<&ControlLoop<MT, NB>> {
        self.control.as_ref()
    }

    /// Tells the host that the target is listening: one `0` byte (see the
    /// module docs). Call it once, after the port is enabled.
    pub fn announce(&mut self) {
        self.port.write_all(&[0]);
    }

    /// Reads bytes until one host message is complete, handles it and sends
    /// the reply (see the module docs).
    pub fn poll(&mut self) -> Event {
        let len = loop {
            let byte = self.port.read_byte();
            if byte == 0 {
                if self.pending == 0 {
                    // An empty frame: a flush or keep-alive, not a message.
                    continue;
                }
                self.pending = 0;
            } else {
                self.pending += 1;
            }
            match self.acc.push(byte, &mut self.msg) {
                None => {}
                Some(Ok(len)) => break len,
                Some(Err(_)) => return self.refuse(LinkError::Malformed),
            }
        };
        let msg = match postcard::from_bytes::<HostMsg<MT>>(&self.msg[..len.min(MAX_LINK_MSG)]) {
            Ok(m) => m,
            Err(_) => return self.refuse(LinkError::Malformed),
        };
        match msg {
            HostMsg::Configure(config) => self.configure(config),
            HostMsg::Radio(frame) => {
                if self.control.is_none() {
                    return self.refuse(LinkError::NotConfigured);
                }
                let mut f = Frame {
                    len: frame.len() as u8,
                    bytes: [0; MAX_FRAME_LEN],
                };
                f.bytes[..frame.len()].copy_from_slice(&frame);
                if self.radio.push_back(f).is_err() {
                    self.radio_dropped += 1;
                }
                Event::Queued
            }
            HostMsg::Step(step) => self.step(&step),
            HostMsg::Finish => {
                let (accepted, rejected) = match &self.control {
                    Some(c) => (c.agent().stats().accepted, c.agent().stats().rejected()),
                    None => (0, 0),
                };
                self.send(&TargetMsg::Finished { accepted, rejected });
                Event::Finished { accepted, rejected }
            }
        }
    }

    #[inline(never)]
    fn configure(&mut self, config: ph_formation_core::AgentConfig<f32, MT>) -> Event {
        self.control = None;
        self.radio.clear();
        self.clock_us = None;
        match UartAgent::new(config) {
            Ok(agent) => {
                let id = agent.id();
                self.control = Some(ControlLoop::new(agent));
                self.send(&TargetMsg::Ready {
                    id,
                    version: LINK_VERSION,
                    max_triangles: MT as u16,
                    max_neighbours: NB as u16,
                });
                Event::Configured(id)
            }
            Err(e) => self.refuse(LinkError::Config(e)),
        }
    }

    fn step(&mut self, step: &LinkStep) -> Event {
        let Some(control) = self.control.as_mut() else {
            return self.refuse(LinkError::NotConfigured);
        };
        let now = match self.clock_us {
            None => seconds_to_us(step.time),
            Some(t) => t + seconds_to_us(step.dt),
        };
        self.clock_us = Some(now);
        let mut board = Board {
            bearings: LinkSensors { step },
            velocity: LinkSensors { step },
            radio: LinkRadio {
                queue: &mut self.radio,
                port: &mut self.port,
            },
            actuator: LinkActuator { force: [0.0; 2] },
            clock: LinkClock { us: now },
        };
        let report = control.tick(&mut board);
        let out = LinkOutput::new(
            &report.output,
            usize::from(report.frames_sent),
            control.agent().stats().rejected(),
        );
        // At most 3 · MT ≤ MAX_LINK_ESTIMATES: never refused for this board.
        match link_estimates(control.agent()) {
            Ok(estimates) if !estimates.is_empty() => {
                send_msg(&mut self.port, &TargetMsg::Estimates(estimates));
            }
            Ok(_) => {}
            Err(e) => send_msg(&mut self.port, &TargetMsg::Error(e)),
        }
        self.send(&TargetMsg::Output(out));
        Event::Ticked(report)
    }

    fn refuse(&mut self, e: LinkError) -> Event {
        self.send(&TargetMsg::Error(e));
        Event::Refused(e)
    }

    fn send(&mut self, msg: &TargetMsg) {
        send_msg(&mut self.port, msg);
    }
}

/// Encodes `msg` (postcard, then COBS with its `0` delimiter) and writes it.
fn send_msg<P: SerialPort>(port: &mut P, msg: &TargetMsg) {
    // The largest `TargetMsg` is `Estimates`: 16 × (5 bytes + f32) + tags.
    const RAW: usize = 192;
    let mut raw = [0u8; RAW];
    let mut cobs = [0u8; RAW + RAW / 254 + 2];
    let Ok(bytes) = postcard::to_slice(msg, &mut raw) else {
        return;
    };
    if let Some(n) = cobs_encode(bytes, &mut cobs) {
        port.write_all(&cobs[..n]);
    }
}

/// Non-negative seconds to whole microseconds (rounded; non-finite or
/// negative gives 0).
fn seconds_to_us(s: f32) -> u64 {
    if s.is_finite() && s > 0.0 {
        // Saturating float-to-int conversion.
        (s * CLOCK_HZ as f32 + 0.5) as u64
    } else {
        0
    }
}

/// Bearing sensor and velocity source: the host's `Step` message.
#[derive(Debug)]
struct LinkSensors<'a> {
    step: &'a LinkStep,
}

impl BearingSensor for LinkSensors<'_> {
    type Error = core::convert::Infallible;

    fn read_bearings(&mut self, out: &mut [Bearing]) -> Result<usize, Self::Error> {
        let mut n = 0;
        for (slot, b) in out.iter_mut().zip(&self.step.bearings) {
            *slot = Bearing {
                neighbour: b.neighbour,
                direction: b.s,
                rate: b.rate,
                range: b.range,
            };
            n += 1;
        }
        Ok(n)
    }

    fn partner_offset(&mut self) -> Result<Option<Vec2>, Self::Error> {
        Ok(self.step.partner_offset)
    }
}

impl VelocitySource for LinkSensors<'_> {
    type Error = core::convert::Infallible;

    fn velocity(&mut self) -> Result<Vec2, Self::Error> {
        Ok(self.step.velocity)
    }
}

/// Radio: receives the queued `Radio` messages, sends `TargetMsg::Radio`.
#[derive(Debug)]
struct LinkRadio<'a, P> {
    queue: &'a mut Deque<Frame, RADIO_QUEUE>,
    port: &'a mut P,
}

impl<P: SerialPort> Radio for LinkRadio<'_, P> {
    type Error = core::convert::Infallible;

    fn send(&mut self, frame: &[u8]) -> Result<(), Self::Error> {
        let mut v = heapless::Vec::new();
        // `frame` is at most MAX_FRAME_LEN long (Agent::frames).
        let _ = v.extend_from_slice(&frame[..frame.len().min(MAX_FRAME_LEN)]);
        send_msg(self.port, &TargetMsg::Radio(v));
        Ok(())
    }

    fn receive(&mut self, buf: &mut [u8; MAX_FRAME_LEN]) -> Result<Option<usize>, Self::Error> {
        Ok(self.queue.pop_front().map(|f| {
            let len = usize::from(f.len).min(MAX_FRAME_LEN);
            buf[..len].copy_from_slice(&f.bytes[..len]);
            len
        }))
    }
}

/// Actuator: keeps the force for the `Output` message.
#[derive(Debug)]
struct LinkActuator {
    force: Vec2,
}

impl Actuator for LinkActuator {
    type Error = core::convert::Infallible;

    fn apply_force(&mut self, force: Vec2) -> Result<(), Self::Error> {
        self.force = force;
        Ok(())
    }
}

/// Clock: the host's simulated time in microseconds.
#[derive(Clone, Copy, Debug)]
struct LinkClock {
    us: u64,
}

impl Clock for LinkClock {
    fn tick_hz(&self) -> u32 {
        CLOCK_HZ
    }

    fn now_ticks(&self) -> u64 {
        self.us
    }
}

#[cfg(target_os = "none")]
pub use usart::Usart1;

#[cfg(target_os = "none")]
mod usart {
    use super::SerialPort;
    use core::ptr::{read_volatile, write_volatile};

    /// RCC base address.
    const RCC: usize = 0x4002_3800;
    /// RCC_AHB1ENR (GPIO clocks).
    const RCC_AHB1ENR: usize = RCC + 0x30;
    /// RCC_APB2ENR (USART1 clock).
    const RCC_APB2ENR: usize = RCC + 0x44;
    const GPIOAEN: u32 = 1 << 0;
    const USART1EN: u32 = 1 << 4;
    /// GPIOA base address (USART1 TX = PA9, RX = PA10, alternate function 7).
    const GPIOA: usize = 0x4002_0000;
    const GPIO_MODER: usize = 0x00;
    const GPIO_AFRH: usize = 0x24;
    /// USART1 base address.
    const USART1: usize = 0x4001_1000;
    const SR: usize = 0x00;
    const DR: usize = 0x04;
    const BRR: usize = 0x08;
    const CR1: usize = 0x0C;
    const SR_RXNE: u32 = 1 << 5;
    const SR_TXE: u32 = 1 << 7;
    const CR1_UE: u32 = 1 << 13;
    const CR1_RXNEIE: u32 = 1 << 5;
    const CR1_TE: u32 = 1 << 3;
    const CR1_RE: u32 = 1 << 2;

    /// The USART1 global interrupt (position 37 in the STM32F405 vector
    /// table). It is never taken (interrupts stay masked by PRIMASK); it only
    /// wakes the core from `wfi` when a byte arrives.
    #[derive(Clone, Copy, Debug)]
    struct Usart1Irq;

    // SAFETY: 37 is the USART1 interrupt of the STM32F4 family.
    unsafe impl cortex_m::interrupt::InterruptNumber for Usart1Irq {
        fn number(self) -> u16 {
            37
        }
    }

    /// `BRR` for 115 200 Bd from the 16 MHz HSI (the reset clock):
    /// 16e6 / 115200 = 138.9 → mantissa 8, fraction 11 (oversampling 16).
    pub const BRR_115200_HSI: u32 = (8 << 4) | 11;

    fn read(addr: usize) -> u32 {
        // SAFETY: `addr` is one of the memory-mapped registers above; reads
        // of these registers have no side effect other than the documented
        // ones (reading DR clears RXNE).
        unsafe { read_volatile(addr as *const u32) }
    }

    fn write(addr: usize, value: u32) {
        // SAFETY: as in `read`; the values written are the documented
        // configuration bits.
        unsafe { write_volatile(addr as *mut u32, value) }
    }

    /// USART1 of an STM32F4 (PA9/PA10), 8N1, polled, no DMA.
    ///
    /// While waiting for a byte the core sleeps in `wfi`: the receive
    /// interrupt is enabled in the USART and the NVIC but never taken
    /// ([`Usart1::init`] masks all interrupts with PRIMASK), it only wakes
    /// the core. Under QEMU this matters: a core spinning on the status
    /// register starves QEMU's I/O thread, which delivers the serial bytes
    /// (about 18 lock-step ticks per second instead of hundreds).
    ///
    /// QEMU's `netduinoplus2` models USART1 (without FIFO) and connects it
    /// to the first `-serial` backend; it ignores the baud rate and the RCC
    /// and GPIO settings, which a real board needs and which are therefore
    /// written anyway.
    #[derive(Debug)]
    pub struct Usart1 {
        _private: (),
    }

    impl Usart1 {
        /// Enables the clocks, routes PA9/PA10 to USART1, enables the
        /// transmitter and receiver with baud-rate register `brr`, and masks
        /// all interrupts (PRIMASK; see the type's docs).
        ///
        /// # Safety
        ///
        /// Takes over USART1, its pins and their RCC bits: nothing else may
        /// use them, and at most one `Usart1` may exist. Interrupts stay
        /// disabled afterwards.
        pub unsafe fn init(brr: u32) -> Self {
            cortex_m::interrupt::disable();
            write(RCC_AHB1ENR, read(RCC_AHB1ENR) | GPIOAEN);
            write(RCC_APB2ENR, read(RCC_APB2ENR) | USART1EN);
            // PA9, PA10: alternate function mode (0b10), AF7.
            let moder = read(GPIOA + GPIO_MODER) & !(0b1111 << 18);
            write(GPIOA + GPIO_MODER, moder | (0b1010 << 18));
            let afrh = read(GPIOA + GPIO_AFRH) & !(0xFF << 4);
            write(GPIOA + GPIO_AFRH, afrh | (0x77 << 4));
            write(USART1 + BRR, brr);
            write(USART1 + CR1, CR1_UE | CR1_TE | CR1_RE | CR1_RXNEIE);
            cortex_m::peripheral::NVIC::unpend(Usart1Irq);
            // SAFETY: PRIMASK is set above, so unmasking the line in the NVIC
            // cannot start a handler; it only lets the line wake `wfi`.
            unsafe { cortex_m::peripheral::NVIC::unmask(Usart1Irq) };
            Usart1 { _private: () }
        }

        /// The next received byte, if one is waiting.
        pub fn try_read_byte(&mut self) -> Option<u8> {
            if read(USART1 + SR) & SR_RXNE != 0 {
                Some(read(USART1 + DR) as u8)
            } else {
                None
            }
        }
    }

    impl SerialPort for Usart1 {
        fn read_byte(&mut self) -> u8 {
            loop {
                if let Some(b) = self.try_read_byte() {
                    return b;
                }
                // The pending bit may be left over from a byte already read;
                // clear it, look once more, then sleep until the line rises.
                cortex_m::peripheral::NVIC::unpend(Usart1Irq);
                if let Some(b) = self.try_read_byte() {
                    return b;
                }
                cortex_m::asm::wfi();
            }
        }

        fn write_all(&mut self, bytes: &[u8]) {
            for &b in bytes {
                while read(USART1 + SR) & SR_TXE == 0 {}
                write(USART1 + DR, u32::from(b));
            }
        }
    }
}

#[cfg(target_os = "none")]
pub use usart::BRR_115200_HSI;
