//! The physics check of a configuration page on the host, before `export` writes it and
//! before `board load` sends anything: the board's own check
//! (`firmware::application::store::physics`, the code its commit runs before writing
//! flash: the page's estimator on a slow sweep of the field, `model_core::control::physics`)
//! on the page built from the parameter file, then a check that the set was fitted on a
//! clutch's channels, field → torque.
//!
//! Channel roles come from the names' units (`numerics::units`, the vocabulary `diagnose`
//! tells a clutch recording by): a field is a channel in tesla (`b`, `B`), a torque one in
//! N·m (`torque`, `T`, `torque_true`) or the board's own estimate (`torque_est`, what
//! `board record` writes). A set fitted on other channels (a damper's displacement `D` in cm
//! and force `F` in N) is refused naming both, unless the physics check already refuses it
//! (then its reason is the error, with the channels added). A file that does not say what it
//! was fitted on (a published or hand-written set) is judged by the physics check alone.

use std::path::{Path, PathBuf};

use firmware::application::store::{self, Refusal};
use model_core::control::physics::{self, PhysicsFault};
use model_core::control::{ConfigImage, PageError};
use thiserror::Error;

use crate::io::params_file::{FittedChannels, ParamsFile};
use crate::numerics::units::unit_of;

/// Why a page is refused before it is written or sent.
#[derive(Debug, Error)]
pub enum PagePhysicsError {
    #[error("{}: refused: {}{}", path.display(), describe(fault, limits), channel_note(channels.as_ref()))]
    Physics { path: PathBuf, fault: PhysicsFault, limits: Limits, channels: Option<(String, String)> },
    #[error(
        "{}: refused: the set was fitted on `{input}` → `{output}` ({}), not on a clutch's field → torque \
         (a channel in T such as `b`, one in N·m such as `torque`); fit it on the clutch's Hall field and \
         torque (`fit --input b --output torque`)",
        path.display(),
        units(input, output)
    )]
    Channels { path: PathBuf, input: String, output: String },
    #[error("{}: refused: the page does not make a controller for the board: {source}", path.display())]
    Page { path: PathBuf, source: PageError },
}

/// The page's figures the messages quote: the swept field and the rating.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Top of the sweep (`b_max`), T.
    pub b_max: f32,
    /// The page's `torque_max`, N·m.
    pub torque_max: f32,
}

/// Refuse the page `img` built from `file` (read from `path`) if its model fails the
/// board's physics check, or if the set was fitted on channels that are not a clutch's
/// field and torque.
pub fn check(file: &ParamsFile, path: &Path, img: &ConfigImage) -> Result<(), PagePhysicsError> {
    let c = img.control.get();
    let limits = Limits { b_max: c.b_max, torque_max: c.torque_max };
    let foreign = file.channels.as_ref().filter(|ch| !clutch_channels(ch));
    let named = || foreign.map(|ch| (ch.input.clone(), ch.output.clone()));
    match store::physics(img) {
        Err(Refusal::Physics(fault)) => {
            return Err(PagePhysicsError::Physics { path: path.to_owned(), fault, limits, channels: named() })
        }
        Err(Refusal::Page(source)) => return Err(PagePhysicsError::Page { path: path.to_owned(), source }),
        Ok(()) => {}
    }
    match foreign {
        Some(ch) => Err(PagePhysicsError::Channels {
            path: path.to_owned(),
            input: ch.input.clone(),
            output: ch.output.clone(),
        }),
        None => Ok(()),
    }
}

/// A field channel: its unit is tesla.
pub fn is_field(name: &str) -> bool {
    unit_of(name) == Some("T")
}

/// A torque channel: its unit is N·m, or the board's estimate as `board record` names it.
pub fn is_torque(name: &str) -> bool {
    unit_of(name) == Some("N·m") || name == "torque_est"
}

/// Fitted from a field to a torque.
pub fn clutch_channels(ch: &FittedChannels) -> bool {
    is_field(&ch.input) && is_torque(&ch.output)
}

fn units(input: &str, output: &str) -> String {
    let u = |n: &str| unit_of(n).unwrap_or("unit unknown");
    format!("{} → {}", u(input), u(output))
}

fn channel_note(ch: Option<&(String, String)>) -> String {
    ch.map(|(i, o)| format!("; it was fitted on `{i}` → `{o}` ({}), not on a clutch's field → torque", units(i, o)))
        .unwrap_or_default()
}

/// The fault in words, with its figures.
fn describe(f: &PhysicsFault, l: &Limits) -> String {
    let sweep = format!("on a slow field sweep (0 → {} T and back, {} s each way)", l.b_max, physics::SWEEP_HALF_S);
    match *f {
        PhysicsFault::NonFinite { b } => {
            format!("the estimate is not finite at {b:.3} T {sweep}: the set overflows the board's f32 arithmetic")
        }
        PhysicsFault::ExceedsRating { at, limit } => format!(
            "the estimate reaches {:.1} N·m at {:.2} T {sweep}, beyond {limit:.1} N·m ({} times the page's rated \
             torque_max of {} N·m); a set in other units or of another device would drive the clutch wrongly",
            at.torque,
            at.b,
            physics::RATING_MARGIN,
            l.torque_max
        ),
        PhysicsFault::Decreasing { high, low, span } => format!(
            "the estimate decreases as the field rises ({:.1} N·m at {:.2} T, {:.1} N·m at {:.2} T: a fall of {:.0} % \
             of the {span:.1} N·m the rising branch spans, at most {:.0} % accepted); a set whose stiffness has the \
             wrong sign would drive the clutch the wrong way",
            low.torque,
            low.b,
            high.torque,
            high.b,
            100.0 * (high.torque - low.torque) / span,
            100.0 * physics::DROP_SHARE
        ),
        PhysicsFault::NotRising { at_zero, at_max, needed } => format!(
            "the estimate hardly rises with the field ({:.2} N·m at 0 T, {:.2} N·m at {:.2} T: less than the {needed:.2} \
             N·m, {:.0} % of the rated torque, the torque loop needs to act on)",
            at_zero.torque,
            at_max.torque,
            at_max.b,
            100.0 * physics::MIN_RISE_SHARE
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_roles_by_unit() {
        assert!(is_field("b") && is_field("B") && !is_field("D") && !is_field("x"));
        assert!(is_torque("torque") && is_torque("torque_est") && is_torque("T") && !is_torque("F"));
        let ch = |i: &str, o: &str| FittedChannels { input: i.into(), output: o.into(), ..Default::default() };
        assert!(clutch_channels(&ch("b", "torque")) && clutch_channels(&ch("b", "torque_est")));
        assert!(!clutch_channels(&ch("D", "F")) && !clutch_channels(&ch("torque", "b")));
    }
}
