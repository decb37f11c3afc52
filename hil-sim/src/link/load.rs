//! `board load`: a `fit --save` file → the configuration page `export` writes → transferred
//! in `ConfigData` frames → committed (the board checks the transfer CRC, validates the
//! page, writes flash, reads it back) → verified (the board reports the running page's CRC).

use std::path::Path;

use model_core::control::config::crc32_update;
use model_core::protocol::{Command, Nack, Response, CHUNK};
use serde::Serialize;

use super::client::{Link, COMMIT_REPLY};
use super::error::{LinkError, PageState};
use crate::io::config_page;
use crate::io::params_file::ParamsFile;
use crate::progress::Progress;

/// What was loaded.
#[derive(Clone, Debug, Serialize)]
pub struct Loaded {
    pub model: String,
    /// Bytes transferred (the page through its CRC).
    pub bytes: usize,
    /// The page's CRC-32, as `export` prints it and the board reports it.
    pub crc: u32,
}

/// Transfers of the whole page before giving up (a frame lost on the line fails the
/// commit's transfer CRC; the transfer then starts again).
const TRANSFERS: u32 = 3;

/// Load `params` into the board on `link`.
pub fn load(link: &mut Link, params: &Path, progress: &dyn Progress) -> Result<Loaded, LinkError> {
    let file = ParamsFile::read(params)?;
    let (_, control) = config_page::firmware_control(&file.model, None)?;
    let img = config_page::firmware_image(&file, params, control)?;
    crate::io::page_physics::check(&file, params, &img)?;
    let page = img.encode();
    let used = usize::from(u16::from_le_bytes([page[6], page[7]])) + 4;
    let sent = &page[..used];
    let want = img.crc();
    let loaded = || Loaded { model: img.model_id().to_owned(), bytes: used, crc: want };
    let before = link.page_crc()?;
    for transfer in 1..=TRANSFERS {
        transfer_page(link, sent, progress)?;
        progress.message("committing (the board validates the page and writes flash)");
        match commit(link, !crc32_update(!0, sent)) {
            Ok(()) => break,
            Err(e @ LinkError::Refused { reason: Nack::Sequence | Nack::TransferCrc, .. }) if transfer < TRANSFERS => {
                progress.message(&format!("{e}; transferring again"));
            }
            // No answer: the commit may or may not have been written. Ask which page runs.
            Err(LinkError::Timeout { ms, .. }) => return after_silence(link, before, want, ms).map(|()| loaded()),
            Err(e) => return Err(e),
        }
    }
    progress.message("verifying");
    match link.page_crc()? {
        got if got == want => Ok(loaded()),
        got => Err(LinkError::Verify { port: link.port().to_owned(), want, got }),
    }
}

/// Begin (in this link's session) and the data frames.
fn transfer_page(link: &mut Link, sent: &[u8], progress: &dyn Progress) -> Result<(), LinkError> {
    progress.stage("transferring the page", sent.chunks(CHUNK).count() as u64);
    let len = sent.len() as u16;
    link.command(|guard| Command::ConfigBegin { guard, len }, "the start of the transfer")?;
    for (k, c) in sent.chunks(CHUNK).enumerate() {
        let mut data = [0u8; CHUNK];
        data[..c.len()].copy_from_slice(c);
        link.send(Command::ConfigData { offset: (k * CHUNK) as u16, len: c.len() as u8, data })?;
        progress.advance(1);
    }
    Ok(())
}

/// The commit, sent once: a second commit of one transfer would be refused as out of
/// sequence even when the first was written and only its answer was lost.
fn commit(link: &mut Link, crc: u32) -> Result<(), LinkError> {
    match link.request_once(Command::ConfigCommit { crc }, "the commit", COMMIT_REPLY)? {
        Response::Ack { .. } => Ok(()),
        r => Err(LinkError::Unexpected { port: link.port().to_owned(), what: "the commit", reply: format!("{r:?}") }),
    }
}

/// The commit went unanswered for `ms`: the page that runs, read back, says whether the
/// load took effect.
fn after_silence(link: &mut Link, before: u32, want: u32, ms: u64) -> Result<(), LinkError> {
    let port = link.port().to_owned();
    match link.page_crc() {
        Ok(got) if got == want => Ok(()),
        Ok(got) => Err(LinkError::CommitUnanswered { port, ms, state: PageState::Old { crc: got, before } }),
        Err(_) => Err(LinkError::CommitUnanswered { port, ms, state: PageState::Unknown }),
    }
}
