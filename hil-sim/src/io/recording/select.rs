//! Which channels play which role, and constants as channels: a scalar variable of the
//! file (or a value on the first row only of a CSV column) named by a role, and the
//! constants given with the recording (`--set V=2.178`, a manifest's `set`), become
//! full-length channels before anything reads them.

use super::{Column, Recording, RecordingError};

/// Which columns play which role (`NAME:K` picks column K of a matrix variable).
#[derive(Clone, Debug, PartialEq)]
pub struct Channels {
    pub time: String,
    pub input: String,
    pub output: String,
    /// Channel driving current/voltage-dependent parameters, if any.
    pub command: Option<String>,
    /// Constant channels given with the recording, for channels the file lacks.
    pub set: Vec<(String, f64)>,
}

impl Default for Channels {
    /// The contract's defaults for an MR clutch: `t`, `b`, `torque`.
    fn default() -> Self {
        Self { time: "t".into(), input: "b".into(), output: "torque".into(), command: None, set: Vec::new() }
    }
}

impl Channels {
    /// The channel names the roles use (time, input, output, command).
    pub fn roles(&self) -> Vec<&str> {
        let mut r = vec![self.time.as_str(), self.input.as_str(), self.output.as_str()];
        r.extend(self.command.as_deref());
        r
    }
}

impl Recording {
    /// Turn the constants `ch` gives (`ch.set`), and the file's own constants a role names,
    /// into full-length channels. A given constant may not shadow a channel of the file (applying
    /// the same constants again changes nothing).
    pub fn apply_constants(&mut self, ch: &Channels) -> Result<(), RecordingError> {
        let n = self.len();
        for (name, v) in &ch.set {
            if let Some(c) = self.columns.iter().find(|c| &c.name == name) {
                // Applied before (the same constant): nothing to do.
                if c.values.iter().all(|x| x == v) {
                    continue;
                }
                return Err(RecordingError::SetShadows { path: self.path.clone(), name: name.clone() });
            }
            self.constants.retain(|c| &c.0 != name);
            self.skipped.retain(|s| &s.name != name);
            self.columns.push(Column { name: name.clone(), values: vec![*v; n] });
        }
        for role in ch.roles() {
            if self.columns.iter().any(|c| c.name == role) {
                continue;
            }
            if let Some(i) = self.constants.iter().position(|c| c.0 == role) {
                let (name, v) = self.constants.remove(i);
                self.columns.push(Column { name, values: vec![v; n] });
            }
        }
        Ok(())
    }
}
