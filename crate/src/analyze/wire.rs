//! The timing side's messages and results as bytes, for running it in another wasm instance.
//!
//! A browser worker has one thread, so the playground runs the timing side ([`Timing`]) in a
//! second worker and ships it the read side's [`TimeMsg`]s in transferred buffers (see
//! [`super::apart`]). Numbers travel as their IEEE bits, little-endian, so both sides see the
//! same values to the bit and the report is the CLI's. Limits and the set-up, rare and
//! nested, travel as JSON (serde_json with `float_roundtrip`, exact for finite numbers).
//! A straight move, nearly every message, carries only what changed since the move before
//! ([`MoveContext`]): the 34 MB corpus file's batches shrank from 62.3 MB (57 bytes a move) to
//! 29.1 MB, which the read side copies out of wasm and the planner's worker reads.

use serde::{Deserialize, Serialize};

use super::accounting::{Pending, TimeBook, TimeMsg, Timing};
use super::toolpath::{MetricsAccumulator, MoveTrace, DEFAULT_CRITICAL_ANGLE_DEG};
use crate::energy::{Accumulator, EnergyOptions};
use crate::error::{Error, ErrorKind};
use crate::machine::{Arc, FanEvent, Heater, Plane, TemperatureEvent};
use crate::plan::{JunctionModel, Limits, Motion, Planner};
use crate::read::{AnalyzeOptions, Reader};

const MOVE: u8 = 0;
const MOTION: u8 = 1;
const DWELL: u8 = 2;
const FLUSH: u8 = 3;
const LIMITS: u8 = 4;
const TEMPERATURE: u8 = 5;
const FAN: u8 = 6;
const SETUP: u8 = 7;
/// A message's kind is the tag's low four bits; a move's tag carries its [`MoveTrace`] in the
/// high four (extruding, infill, joins), which are zero for every other kind.
const KIND: u8 = 0x0F;
const TRACE_SHIFT: u8 = 4;

fn trace_bits(t: MoveTrace) -> u8 {
    (u8::from(t.extruding) | u8::from(t.infill) << 1 | u8::from(t.joins) << 2) << TRACE_SHIFT
}

fn trace_of(tag: u8) -> MoveTrace {
    let bits = tag >> TRACE_SHIFT;
    MoveTrace {
        extruding: bits & 1 != 0,
        infill: bits & 2 != 0,
        joins: bits & 4 != 0,
    }
}

/// What the timing side starts from: the limits and junction model the file is planned with,
/// and the energy model.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TimingSetup {
    pub limits: Limits,
    pub model: JunctionModel,
    pub energy: EnergyOptions,
    /// The machine profile's name (the energy model's servo preset depends on it).
    pub profile: String,
}

impl TimingSetup {
    /// The set-up of a file about to be read by `reader`.
    pub(crate) fn of(reader: &Reader, options: &AnalyzeOptions) -> Self {
        TimingSetup {
            limits: reader.setup.limits.clone(),
            model: reader.setup.model,
            energy: options.energy.clone().unwrap_or_default(),
            profile: reader.setup.profile.name.clone(),
        }
    }

    /// A fresh energy accumulator for this set-up.
    pub fn accumulator(&self) -> Accumulator {
        Accumulator::new(&self.energy, &self.profile)
    }

    /// A timing side at the start of the file.
    pub fn timing(&self) -> Timing {
        Timing::new(
            Planner::new(self.limits.clone(), self.model),
            self.accumulator(),
        )
    }
}

/// A message from the read side to the timing side.
#[derive(Debug)]
pub enum WireMsg {
    Setup(Box<TimingSetup>),
    Time(TimeMsg),
}

fn garbled(reason: &'static str) -> Error {
    Error::new(0, 0, ErrorKind::Transfer { reason })
}

fn put_f64s(out: &mut Vec<u8>, v: &[f64]) {
    for x in v {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_json<T: Serialize>(out: &mut Vec<u8>, v: &T) {
    // Serialising these plain structs of finite numbers cannot fail.
    let json = serde_json::to_vec(v).unwrap_or_default();
    put_u32(out, json.len() as u32);
    out.extend_from_slice(&json);
}

fn put_layers(out: &mut Vec<u8>, layers: (u32, u32)) {
    put_u32(out, layers.0);
    put_u32(out, layers.1);
}

/// Appends the set-up message.
pub fn put_setup(out: &mut Vec<u8>, setup: &TimingSetup) {
    out.push(SETUP);
    put_json(out, setup);
}

/// What a straight move repeats from the one before, so that the wire carries only what
/// changed: nearly every move of a sliced file has the previous feed rate, slot and layers,
/// the next line, and no Z (or, for a travel, no E) displacement. Both sides keep one, updated
/// by every move in order, so the values they rebuild are the sent ones to the bit.
#[derive(Debug, Clone, Copy, Default)]
pub struct MoveContext {
    feed_bits: u64,
    line: u32,
    slot: u32,
    layers: (u32, u32),
}

/// Flag bits of a straight move after its tag: which of its values are written.
const AXIS_SHIFT: u8 = 0; // bits 0–3: X, Y, Z, E displacement not +0.0
const FEED: u8 = 1 << 4;
const LINE: u8 = 1 << 5; // not the line after the previous move's
const SLOT: u8 = 1 << 6;
const LAYERS: u8 = 1 << 7;

/// Appends one message; `ctx` is what the earlier moves sent.
pub fn put_msg(out: &mut Vec<u8>, ctx: &mut MoveContext, msg: &TimeMsg) {
    match msg {
        &TimeMsg::Move {
            delta,
            feed_mm_s,
            line,
            slot,
            layers,
            trace,
        } => {
            out.push(MOVE | trace_bits(trace));
            put_move(out, ctx, delta, feed_mm_s, line, slot, layers);
        }
        TimeMsg::Motion {
            m,
            slot,
            layers,
            trace,
        } => {
            out.push(MOTION | trace_bits(*trace));
            put_motion(out, m);
            put_u32(out, *slot);
            put_layers(out, *layers);
        }
        TimeMsg::Dwell { secs, layers } => {
            out.push(DWELL);
            put_f64s(out, &[*secs]);
            put_layers(out, *layers);
        }
        TimeMsg::Flush => out.push(FLUSH),
        TimeMsg::Limits(l) => {
            out.push(LIMITS);
            put_json(out, l.as_ref());
        }
        TimeMsg::Event { before, event } => put_event(out, *before, event),
    }
}

/// A straight move after its tag: its flags, then only the values `ctx` does not already give
/// (a displacement component is left out only when it is +0.0, so −0.0 keeps its sign).
fn put_move(
    out: &mut Vec<u8>,
    ctx: &mut MoveContext,
    delta: [f64; 4],
    feed_mm_s: f64,
    line: u32,
    slot: u32,
    layers: (u32, u32),
) {
    let mut flags = 0u8;
    for (i, d) in delta.iter().enumerate() {
        if d.to_bits() != 0 {
            flags |= 1 << (AXIS_SHIFT + i as u8);
        }
    }
    let feed_bits = feed_mm_s.to_bits();
    flags |= if feed_bits != ctx.feed_bits { FEED } else { 0 };
    flags |= if line != ctx.line.wrapping_add(1) {
        LINE
    } else {
        0
    };
    flags |= if slot != ctx.slot { SLOT } else { 0 };
    flags |= if layers != ctx.layers { LAYERS } else { 0 };
    out.push(flags);
    for (i, d) in delta.iter().enumerate() {
        if flags & (1 << (AXIS_SHIFT + i as u8)) != 0 {
            out.extend_from_slice(&d.to_le_bytes());
        }
    }
    if flags & FEED != 0 {
        out.extend_from_slice(&feed_bits.to_le_bytes());
    }
    if flags & LINE != 0 {
        put_u32(out, line);
    }
    if flags & SLOT != 0 {
        put_u32(out, slot);
    }
    if flags & LAYERS != 0 {
        put_layers(out, layers);
    }
    *ctx = MoveContext {
        feed_bits,
        line,
        slot,
        layers,
    };
}

fn put_motion(out: &mut Vec<u8>, m: &Motion) {
    put_u32(out, m.line);
    put_f64s(out, &m.delta);
    put_f64s(out, &[m.feed_mm_s, m.rotary_time_s]);
    match &m.arc {
        None => out.push(0),
        Some(a) => {
            out.push(1 + plane_code(a.plane));
            put_f64s(
                out,
                &[a.center[0], a.center[1], a.radius, a.sweep, a.start_angle],
            );
        }
    }
}

fn put_event(out: &mut Vec<u8>, before: u64, event: &Pending) {
    match *event {
        Pending::Temperature {
            line,
            heater,
            target_c,
            wait,
        } => {
            out.push(TEMPERATURE);
            out.extend_from_slice(&before.to_le_bytes());
            put_u32(out, line);
            put_heater(out, heater);
            put_f64s(out, &[target_c]);
            out.push(u8::from(wait));
        }
        Pending::Fan { line, index, speed } => {
            out.push(FAN);
            out.extend_from_slice(&before.to_le_bytes());
            put_u32(out, line);
            out.extend_from_slice(&index.to_le_bytes());
            put_f64s(out, &[speed]);
        }
    }
}

fn plane_code(p: Plane) -> u8 {
    match p {
        Plane::Xy => 0,
        Plane::Zx => 1,
        Plane::Yz => 2,
    }
}

fn put_heater(out: &mut Vec<u8>, h: Heater) {
    let (code, tool) = match h {
        Heater::Hotend(t) => (0, t),
        Heater::Bed => (1, 0),
        Heater::Chamber => (2, 0),
    };
    out.push(code);
    out.extend_from_slice(&tool.to_le_bytes());
}

/// Reads values back in the order they were put.
struct Cursor<'a> {
    bytes: &'a [u8],
}

impl<'a> Cursor<'a> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], Error> {
        let (head, rest) = self
            .bytes
            .split_first_chunk::<N>()
            .ok_or_else(|| garbled("cut short"))?;
        self.bytes = rest;
        Ok(*head)
    }

    fn u8(&mut self) -> Result<u8, Error> {
        Ok(self.take::<1>()?[0])
    }

    fn u16(&mut self) -> Result<u16, Error> {
        Ok(u16::from_le_bytes(self.take()?))
    }

    fn u32(&mut self) -> Result<u32, Error> {
        Ok(u32::from_le_bytes(self.take()?))
    }

    fn u64(&mut self) -> Result<u64, Error> {
        Ok(u64::from_le_bytes(self.take()?))
    }

    fn f64(&mut self) -> Result<f64, Error> {
        Ok(f64::from_le_bytes(self.take()?))
    }

    fn f64s<const N: usize>(&mut self) -> Result<[f64; N], Error> {
        let mut v = [0.0; N];
        for x in &mut v {
            *x = self.f64()?;
        }
        Ok(v)
    }

    fn layers(&mut self) -> Result<(u32, u32), Error> {
        Ok((self.u32()?, self.u32()?))
    }

    fn json<T: for<'de> Deserialize<'de>>(&mut self) -> Result<T, Error> {
        let n = self.u32()? as usize;
        if n > self.bytes.len() {
            return Err(garbled("cut short"));
        }
        let (json, rest) = self.bytes.split_at(n);
        self.bytes = rest;
        serde_json::from_slice(json).map_err(|_| garbled("bad JSON"))
    }

    fn heater(&mut self) -> Result<Heater, Error> {
        let (code, tool) = (self.u8()?, self.u16()?);
        match code {
            0 => Ok(Heater::Hotend(tool)),
            1 => Ok(Heater::Bed),
            2 => Ok(Heater::Chamber),
            _ => Err(garbled("unknown heater")),
        }
    }

    fn motion(&mut self) -> Result<Motion, Error> {
        let line = self.u32()?;
        let delta = self.f64s::<4>()?;
        let [feed_mm_s, rotary_time_s] = self.f64s::<2>()?;
        let arc = match self.u8()? {
            0 => None,
            code @ 1..=3 => {
                let [c0, c1, radius, sweep, start_angle] = self.f64s::<5>()?;
                let plane = [Plane::Xy, Plane::Zx, Plane::Yz][usize::from(code - 1)];
                Some(Arc {
                    plane,
                    center: [c0, c1],
                    radius,
                    sweep,
                    start_angle,
                })
            }
            _ => return Err(garbled("unknown arc plane")),
        };
        Ok(Motion {
            line,
            delta,
            arc,
            feed_mm_s,
            rotary_time_s,
        })
    }

    /// A straight move [`put_move`] wrote, its missing values from `ctx`, which it updates.
    fn straight_move(&mut self, ctx: &mut MoveContext, trace: MoveTrace) -> Result<TimeMsg, Error> {
        let flags = self.u8()?;
        let mut delta = [0.0; 4];
        for (i, d) in delta.iter_mut().enumerate() {
            if flags & (1 << (AXIS_SHIFT + i as u8)) != 0 {
                *d = self.f64()?;
            }
        }
        if flags & FEED != 0 {
            ctx.feed_bits = self.u64()?;
        }
        ctx.line = if flags & LINE != 0 {
            self.u32()?
        } else {
            ctx.line.wrapping_add(1)
        };
        if flags & SLOT != 0 {
            ctx.slot = self.u32()?;
        }
        if flags & LAYERS != 0 {
            ctx.layers = self.layers()?;
        }
        Ok(TimeMsg::Move {
            delta,
            feed_mm_s: f64::from_bits(ctx.feed_bits),
            line: ctx.line,
            slot: ctx.slot,
            layers: ctx.layers,
            trace,
        })
    }

    fn msg(&mut self, ctx: &mut MoveContext) -> Result<WireMsg, Error> {
        let tag = self.u8()?;
        let msg = match tag & KIND {
            MOVE => self.straight_move(ctx, trace_of(tag))?,
            MOTION => TimeMsg::Motion {
                m: Box::new(self.motion()?),
                slot: self.u32()?,
                layers: self.layers()?,
                trace: trace_of(tag),
            },
            _ if tag & !KIND != 0 => return Err(garbled("unknown message")),
            DWELL => TimeMsg::Dwell {
                secs: self.f64()?,
                layers: self.layers()?,
            },
            FLUSH => TimeMsg::Flush,
            LIMITS => TimeMsg::Limits(Box::new(self.json()?)),
            TEMPERATURE => TimeMsg::Event {
                before: self.u64()?,
                event: Pending::Temperature {
                    line: self.u32()?,
                    heater: self.heater()?,
                    target_c: self.f64()?,
                    wait: self.u8()? != 0,
                },
            },
            FAN => TimeMsg::Event {
                before: self.u64()?,
                event: Pending::Fan {
                    line: self.u32()?,
                    index: self.u16()?,
                    speed: self.f64()?,
                },
            },
            SETUP => return Ok(WireMsg::Setup(Box::new(self.json()?))),
            _ => return Err(garbled("unknown message")),
        };
        Ok(WireMsg::Time(msg))
    }
}

/// Calls `f` with each message of a batch, in order; `ctx` is what the earlier batches' moves
/// sent.
pub fn read_msgs(
    bytes: &[u8],
    ctx: &mut MoveContext,
    mut f: impl FnMut(WireMsg) -> Result<(), Error>,
) -> Result<(), Error> {
    let mut c = Cursor { bytes };
    while !c.bytes.is_empty() {
        f(c.msg(ctx)?)?;
    }
    Ok(())
}

fn put_pairs(out: &mut Vec<u8>, v: &[(f64, f64)]) {
    put_u32(out, v.len() as u32);
    for &(a, b) in v {
        put_f64s(out, &[a, b]);
    }
}

/// The timing side's results: its planned time and its book (events all stamped).
pub fn put_book(out: &mut Vec<u8>, time_s: f64, book: &TimeBook) {
    put_f64s(out, &[time_s]);
    put_f64s(out, &book.energy.running_sums());
    put_pairs(out, &book.feature_time);
    put_f64s(out, &[book.travel_time.0, book.travel_time.1]);
    put_pairs(out, &book.layer_time[0]);
    put_pairs(out, &book.layer_time[1]);
    put_u32(out, book.temperatures.len() as u32);
    for t in &book.temperatures {
        put_u32(out, t.line);
        put_f64s(out, &[t.time_s, t.target_c]);
        put_heater(out, t.heater);
        out.push(u8::from(t.wait));
    }
    put_u32(out, book.fans.len() as u32);
    for f in &book.fans {
        put_u32(out, f.line);
        put_f64s(out, &[f.time_s, f.speed]);
        out.extend_from_slice(&f.index.to_le_bytes());
    }
    match &book.toolpath {
        None => out.push(0),
        Some(t) => {
            out.push(1);
            for w in t.to_words() {
                out.extend_from_slice(&w.to_le_bytes());
            }
        }
    }
}

impl Cursor<'_> {
    /// A count of items of at least `item` bytes each, checked against what is left (a garbled
    /// count must not reserve gigabytes).
    fn count(&mut self, item: usize) -> Result<usize, Error> {
        let n = self.u32()? as usize;
        if n.saturating_mul(item) > self.bytes.len() {
            return Err(garbled("cut short"));
        }
        Ok(n)
    }

    fn pairs(&mut self) -> Result<Vec<(f64, f64)>, Error> {
        let n = self.count(16)?;
        (0..n).map(|_| Ok((self.f64()?, self.f64()?))).collect()
    }

    fn temperature(&mut self) -> Result<TemperatureEvent, Error> {
        let line = self.u32()?;
        let [time_s, target_c] = self.f64s::<2>()?;
        Ok(TemperatureEvent {
            line,
            time_s,
            target_c,
            heater: self.heater()?,
            wait: self.u8()? != 0,
        })
    }

    fn fan(&mut self) -> Result<FanEvent, Error> {
        let line = self.u32()?;
        let [time_s, speed] = self.f64s::<2>()?;
        Ok(FanEvent {
            line,
            time_s,
            speed,
            index: self.u16()?,
        })
    }
}

/// The planned time and the book [`put_book`] wrote; `energy` is a fresh accumulator set up as
/// the timing side's was.
pub fn read_book(bytes: &[u8], mut energy: Accumulator) -> Result<(f64, TimeBook), Error> {
    let mut c = Cursor { bytes };
    let time_s = c.f64()?;
    energy.set_running_sums(c.f64s::<10>()?);
    let mut book = TimeBook::new(energy);
    book.feature_time = c.pairs()?;
    book.travel_time = (c.f64()?, c.f64()?);
    book.layer_time = [c.pairs()?, c.pairs()?];
    let n = c.count(24)?;
    book.temperatures = (0..n).map(|_| c.temperature()).collect::<Result<_, _>>()?;
    let n = c.count(22)?;
    book.fans = (0..n).map(|_| c.fan()).collect::<Result<_, _>>()?;
    book.toolpath = match c.u8()? {
        0 => None,
        1 => {
            let mut w = [0; 8];
            for x in &mut w {
                *x = c.u64()?;
            }
            Some(MetricsAccumulator::from_words(
                DEFAULT_CRITICAL_ANGLE_DEG,
                w,
            ))
        }
        _ => return Err(garbled("bad toolpath flag")),
    };
    if !c.bytes.is_empty() {
        return Err(garbled("trailing bytes"));
    }
    Ok((time_s, book))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyze::accounting::TRAVEL;

    fn straight(delta: [f64; 4], feed: f64, line: u32, slot: u32, layer: u32) -> TimeMsg {
        TimeMsg::Move {
            delta,
            feed_mm_s: feed,
            line,
            slot,
            layers: (layer, layer),
            trace: MoveTrace {
                extruding: delta[3] > 0.0,
                infill: slot == 1,
                joins: line % 3 != 0,
            },
        }
    }

    /// Moves that repeat their context and moves that change every part of it (−0.0 and NaN
    /// displacements, a line that goes back, a feed, slot and layer change), an arc, a dwell,
    /// events: read back as they were sent, with batches cut anywhere between messages.
    #[test]
    fn messages_read_back_as_sent_across_batches() {
        let msgs = vec![
            straight([1.0, 2.0, 0.0, 0.05], 40.0, 10, 0, 0),
            straight([1.5, 0.0, 0.0, 0.05], 40.0, 11, 0, 0),
            straight([-0.0, 3.0, 0.2, 0.0], 150.0, 12, TRAVEL, 1),
            straight([f64::NAN, 0.0, 0.0, -0.8], 35.0, 9, 1, 1),
            straight([0.0; 4], 35.0, 10, 1, 2),
            TimeMsg::Motion {
                m: Box::new(Motion {
                    line: 11,
                    delta: [2.0, 2.0, 0.0, 0.1],
                    arc: Some(Arc {
                        plane: Plane::Zx,
                        center: [1.0, 1.5],
                        radius: 2.5,
                        sweep: -1.2,
                        start_angle: 0.3,
                    }),
                    feed_mm_s: 30.0,
                    rotary_time_s: 0.0,
                }),
                slot: 1,
                layers: (2, 2),
                trace: MoveTrace {
                    extruding: true,
                    infill: true,
                    joins: true,
                },
            },
            straight([1.0, 1.0, 0.0, 0.02], 35.0, 12, 1, 2),
            TimeMsg::Dwell {
                secs: 1.5,
                layers: (2, 2),
            },
            TimeMsg::Flush,
            TimeMsg::Event {
                before: 7,
                event: Pending::Fan {
                    line: 13,
                    index: 1,
                    speed: 0.5,
                },
            },
            straight([1.0, 1.0, 0.0, 0.02], 35.0, 14, 1, 2),
        ];
        let mut sent = MoveContext::default();
        let mut parts: Vec<Vec<u8>> = Vec::new();
        for (i, m) in msgs.iter().enumerate() {
            if i % 3 == 0 {
                parts.push(Vec::new());
            }
            if let Some(p) = parts.last_mut() {
                put_msg(p, &mut sent, m);
            }
        }
        let mut received = MoveContext::default();
        let mut back = Vec::new();
        for p in &parts {
            read_msgs(p, &mut received, |w| {
                if let WireMsg::Time(m) = w {
                    back.push(format!("{m:?}"));
                }
                Ok(())
            })
            .unwrap();
        }
        let sent: Vec<String> = msgs.iter().map(|m| format!("{m:?}")).collect();
        assert_eq!(back, sent);
        // A repeated move costs its tag, its flags and its non-zero displacements.
        let mut ctx = MoveContext::default();
        let mut first = Vec::new();
        put_msg(&mut first, &mut ctx, &msgs[0]);
        let mut next = Vec::new();
        put_msg(&mut next, &mut ctx, &msgs[1]);
        assert_eq!(next.len(), 2 + 2 * 8);
    }

    #[test]
    fn trace_bits_on_a_message_that_has_none_are_an_error() {
        let mut ctx = MoveContext::default();
        for tag in [DWELL | 1 << TRACE_SHIFT, FLUSH | 4 << TRACE_SHIFT] {
            let bytes = [tag, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
            assert!(read_msgs(&bytes, &mut ctx, |_| Ok(())).is_err(), "{tag}");
        }
    }
}
