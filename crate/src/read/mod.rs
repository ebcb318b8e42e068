//! One way through a file: every pass that needs a file's moves (`analyze`, `path`, the infill
//! program, VTG's move sources, the orientation smoother's motion lines) is a `Fold` over the
//! `Reader`.
//!
//! The reader owns what all of them must read the same way: set-up (`prepare`: options,
//! extrusion mode, prescan, machine profile, junction model and starting limits), the machine
//! state, the limits the file's own commands set (`M201`–`M205`, `SET_VELOCITY_LIMIT`), the
//! limits in force at the first extrusion, and the layer count. For each line it classifies the
//! comment (layer marker, feature, other), applies a limit command or else the command to the
//! machine, and tells the fold what happened, in that order. A change to how a command is read
//! lands here once.
//!
//! ```
//! use quietpath::read::read_moves;
//! let gcode = b"M83\n;LAYER_CHANGE\nG1 X10 Y0 E0.5 F1200\nG1 X10 Y10 E0.5\n";
//! let moves = read_moves(gcode, &Default::default()).unwrap();
//! assert_eq!(moves.len(), 2);
//! assert_eq!(moves[1].to[1], 10.0);
//! ```

mod layers;
pub mod prescan;
mod setup;

pub(crate) use layers::LayerTracker;
pub use layers::{LayerSource, LayerSummary, NO_LAYER};
pub(crate) use setup::{prepare, Setup};
pub use setup::{AnalyzeOptions, ExtrusionModeOption};

use crate::error::Error;
use crate::gcode::{self, classify_comment, Line, Marker, RawLine};
use crate::machine::{Event, Machine, Move};
use crate::plan::Limits;

/// What the reader does with a line after [`Fold::line`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Flow {
    /// Read it: comment, limits, machine.
    Read,
    /// Leave it: the fold has taken it whole.
    Skip,
}

/// Where the reader is when it tells a fold of an event.
#[derive(Debug, Clone, Copy)]
pub(crate) struct At<'r> {
    /// 1-based line number.
    pub line: u32,
    /// The machine after the line.
    pub machine: &'r Machine,
    /// Layer of the line by marker and by counting (which one the file uses is known only at
    /// the end, from [`LayerTracker::finish`]).
    pub layers: (u32, u32),
    /// The file runs on Klipper ([`Setup::klipper`]).
    pub klipper: bool,
}

impl At<'_> {
    /// Whether `m` is homing that takes no planned time: `G28` on Klipper, whose duration
    /// depends on the printer (endstops, homing speeds, probing macros) and no file tells. It
    /// empties the look-ahead (the toolhead stops) and is counted apart. Marlin-style files
    /// keep timing `G28` as a move to 0, as PrusaSlicer's estimator does.
    pub fn untimed_homing(&self, m: &Move) -> bool {
        self.klipper && matches!(m.kind, crate::machine::MoveKind::Home)
    }
}

/// A pass over a file. Every method has a default that does nothing, so a fold says only what
/// it keeps.
pub(crate) trait Fold {
    /// Every line first, parsed (`Some`) or skipped by the lenient parser (`None`).
    fn line(&mut self, _raw: &RawLine<'_>, _line: Option<&Line<'_>>) -> Result<Flow, Error> {
        Ok(Flow::Read)
    }
    /// A layer marker; `machine` is the state before the line's command.
    fn layer_marker(&mut self, _machine: &Machine) {}
    /// A feature marker (`;TYPE:…` and its equivalents).
    fn feature(&mut self, _name: &str, _machine: &Machine) {}
    /// A comment that is no marker.
    fn comment(&mut self, _comment: &[u8]) {}
    /// The line's command set new limits (the command goes no further).
    fn limits(&mut self, _limits: &Limits, _machine: &Machine) {}
    /// The line's command, about to be applied to `machine`.
    fn command(&mut self, _line: &Line<'_>, _machine: &Machine) {}
    /// The machine did something.
    fn event(&mut self, _line: &Line<'_>, _event: &Event, _at: At<'_>) -> Result<(), Error> {
        Ok(())
    }
}

/// The fold that keeps nothing (the other of a [`Both`] where one is wanted).
impl Fold for () {}

/// Two folds fed by one pass, the first told of each thing before the second: a caller that
/// needs two folds of the same file reads and parses it once. A line is read where either fold
/// reads it; the one that asked to skip it is then told of it as well, so a fold paired here
/// must take a line it would skip as it takes any other line of its kind.
pub(crate) struct Both<'a, A, B>(pub &'a mut A, pub &'a mut B);

impl<A: Fold, B: Fold> Fold for Both<'_, A, B> {
    fn line(&mut self, raw: &RawLine<'_>, line: Option<&Line<'_>>) -> Result<Flow, Error> {
        let (a, b) = (self.0.line(raw, line)?, self.1.line(raw, line)?);
        Ok(if a == Flow::Read || b == Flow::Read {
            Flow::Read
        } else {
            Flow::Skip
        })
    }
    fn layer_marker(&mut self, machine: &Machine) {
        self.0.layer_marker(machine);
        self.1.layer_marker(machine);
    }
    fn feature(&mut self, name: &str, machine: &Machine) {
        self.0.feature(name, machine);
        self.1.feature(name, machine);
    }
    fn comment(&mut self, comment: &[u8]) {
        self.0.comment(comment);
        self.1.comment(comment);
    }
    fn limits(&mut self, limits: &Limits, machine: &Machine) {
        self.0.limits(limits, machine);
        self.1.limits(limits, machine);
    }
    fn command(&mut self, line: &Line<'_>, machine: &Machine) {
        self.0.command(line, machine);
        self.1.command(line, machine);
    }
    fn event(&mut self, line: &Line<'_>, event: &Event, at: At<'_>) -> Result<(), Error> {
        self.0.event(line, event, at)?;
        self.1.event(line, event, at)
    }
}

/// Set-up and state of one pass over a file.
#[derive(Debug)]
pub(crate) struct Reader {
    /// What the pass started with.
    pub setup: Setup,
    /// The machine, after the lines read so far.
    pub machine: Machine,
    /// Limits in force after the lines read so far.
    pub limits: Limits,
    /// Limits in force at the first extruding move, once there was one.
    pub print_limits: Option<Limits>,
    /// Layers counted so far.
    pub layers: LayerTracker,
}

impl Reader {
    /// Prepares a pass over `input` (see [`prepare`]).
    pub fn new(input: &[u8], options: &AnalyzeOptions) -> Result<Self, Error> {
        let setup = prepare(input, options)?;
        Ok(Self {
            machine: setup.machine(),
            limits: setup.limits.clone(),
            print_limits: None,
            layers: LayerTracker::new(),
            setup,
        })
    }

    /// The limits to report for the file: those at the first extrusion, else the last.
    pub fn limits_in_force(&self) -> &Limits {
        self.print_limits.as_ref().unwrap_or(&self.limits)
    }

    /// Reads every line of `input` into `fold`.
    pub fn read(&mut self, input: &[u8], fold: &mut impl Fold) -> Result<(), Error> {
        let Self {
            setup,
            machine,
            limits,
            print_limits,
            layers,
        } = self;
        let units = setup.units;
        // Klipper reads its limit commands its own way (see `Limits::apply_klipper_command`).
        let klipper = setup.klipper();
        let version = setup.klipper_version;
        gcode::for_each_line(
            input,
            setup.strictness,
            &mut setup.warnings,
            |raw, line, warnings| {
                if fold.line(raw, line)? == Flow::Skip {
                    return Ok(());
                }
                let Some(line) = line else { return Ok(()) };
                if let Some(comment) = line.comment {
                    match classify_comment(comment) {
                        Some(Marker::Layer { kind, z }) => {
                            layers.marker(kind, z, raw.number);
                            fold.layer_marker(machine);
                        }
                        Some(Marker::Feature(name)) => fold.feature(name, machine),
                        None => fold.comment(comment),
                    }
                }
                let limit_command = if klipper {
                    limits.apply_klipper_command(line, version)
                } else {
                    limits.apply_command(line, units)
                };
                if limit_command {
                    fold.limits(limits, machine);
                    return Ok(());
                }
                fold.command(line, machine);
                // By reference: a move is a few hundred bytes, not worth a copy.
                let Some(event) = &machine.apply(raw.number, line, warnings) else {
                    return Ok(());
                };
                if let Event::Move(m) = event {
                    if print_limits.is_none() && m.is_extruding() {
                        *print_limits = Some(limits.clone());
                    }
                    layers.motion(m);
                }
                let at = At {
                    line: raw.number,
                    machine,
                    layers: layers.current(),
                    klipper,
                };
                fold.event(line, event, at)
            },
        )
    }
}

/// Every move of `input` as the machine makes it, read as every pass reads it. (A simple fold,
/// for callers that want the moves and nothing else.)
pub fn read_moves(input: &[u8], options: &AnalyzeOptions) -> Result<Vec<Move>, Error> {
    #[derive(Default)]
    struct Moves(Vec<Move>);
    impl Fold for Moves {
        fn event(&mut self, _: &Line<'_>, event: &Event, _: At<'_>) -> Result<(), Error> {
            if let Event::Move(m) = event {
                self.0.push(*m);
            }
            Ok(())
        }
    }
    let mut moves = Moves::default();
    Reader::new(input, options)?.read(input, &mut moves)?;
    Ok(moves.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records what the reader tells a fold, in order.
    #[derive(Default)]
    struct Log(Vec<String>);

    impl Fold for Log {
        fn line(&mut self, raw: &RawLine<'_>, line: Option<&Line<'_>>) -> Result<Flow, Error> {
            let skip =
                line.is_some_and(|l| l.comment.is_some_and(|c| c.trim_ascii() == b"skip me"));
            self.0.push(format!("line {}", raw.number));
            Ok(if skip { Flow::Skip } else { Flow::Read })
        }
        fn layer_marker(&mut self, _: &Machine) {
            self.0.push("layer".into());
        }
        fn feature(&mut self, name: &str, _: &Machine) {
            self.0.push(format!("feature {name}"));
        }
        fn comment(&mut self, c: &[u8]) {
            self.0
                .push(format!("comment {}", String::from_utf8_lossy(c).trim()));
        }
        fn limits(&mut self, limits: &Limits, _: &Machine) {
            self.0
                .push(format!("limits {}", limits.max_acceleration[0].value));
        }
        fn command(&mut self, _: &Line<'_>, m: &Machine) {
            self.0.push(format!("command at x={}", m.position()[0]));
        }
        fn event(&mut self, _: &Line<'_>, e: &Event, at: At<'_>) -> Result<(), Error> {
            if let Event::Move(m) = e {
                let x = at.machine.position()[0];
                self.0.push(format!(
                    "move to x={} layer {:?} now x={x}",
                    m.to[0], at.layers
                ));
            }
            Ok(())
        }
    }

    #[test]
    fn a_fold_hears_markers_limits_commands_and_events_in_line_order() {
        let gcode =
            b";LAYER_CHANGE\n;TYPE:Perimeter\nM201 X900 Y900\nG1 X5 E1 F600 ; hi\n; skip me\n";
        let mut reader = Reader::new(gcode, &AnalyzeOptions::default()).unwrap();
        let mut log = Log::default();
        reader.read(gcode, &mut log).unwrap();
        let expected = [
            "line 1",
            "layer",
            "command at x=0",
            "line 2",
            "feature Perimeter",
            "command at x=0",
            "line 3",
            "limits 900",
            "line 4",
            "comment hi",
            "command at x=0",
            "move to x=5 layer (0, 0) now x=5",
            "line 5",
        ];
        assert_eq!(log.0, expected);
        // The limit command went to the limits, not the machine; they were in force at the
        // first extrusion.
        assert_eq!(reader.limits_in_force().max_acceleration[0].value, 900.0);
    }

    #[test]
    fn limits_in_force_are_those_of_the_first_extrusion() {
        let gcode = b"M83\nM201 X900\nG1 X5 E1 F600\nM201 X100\nG1 X9 E1\n";
        let mut reader = Reader::new(gcode, &AnalyzeOptions::default()).unwrap();
        reader.read(gcode, &mut Log::default()).unwrap();
        assert_eq!(reader.limits_in_force().max_acceleration[0].value, 900.0);
        assert_eq!(reader.limits.max_acceleration[0].value, 100.0);
        assert_eq!(
            read_moves(gcode, &AnalyzeOptions::default()).unwrap().len(),
            2
        );
    }
}
