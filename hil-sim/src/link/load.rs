//! `board load`: a `fit --save` file → the configuration page `export` writes → transferred
//! in `ConfigData` frames → committed (the board checks the transfer CRC, validates the
//! page, writes flash, reads it back) → verified (the board reports the running page's CRC).

use std::path::Path;

use model_core::control::config::crc32_update;
use model_core::protocol::{Command, Response, CHUNK};
use serde::Serialize;

use super::client::{Link, COMMIT_REPLY, REPLY};
use super::error::LinkError;
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
    let page = img.encode();
    let used = usize::from(u16::from_le_bytes([page[6], page[7]])) + 4;
    let sent = &page[..used];
    let transfer_crc = !crc32_update(!0, sent);
    let chunks = sent.chunks(CHUNK).count() as u64;
    let mut last = None;
    for _ in 0..TRANSFERS {
        progress.stage("transferring the page", chunks);
        link.ack(Command::ConfigBegin { len: used as u16 }, "the start of the transfer")?;
        for (k, c) in sent.chunks(CHUNK).enumerate() {
            let mut data = [0u8; CHUNK];
            data[..c.len()].copy_from_slice(c);
            link.send(Command::ConfigData { offset: (k * CHUNK) as u16, len: c.len() as u8, data })?;
            progress.advance(1);
        }
        progress.message("committing (the board validates the page and writes flash)");
        match link.request(Command::ConfigCommit { crc: transfer_crc }, "the commit", COMMIT_REPLY) {
            Ok(Response::Ack(_)) => {
                last = None;
                break;
            }
            Ok(r) => {
                return Err(LinkError::Unexpected {
                    port: link.port().to_owned(),
                    what: "the commit",
                    reply: format!("{r:?}"),
                })
            }
            Err(e @ LinkError::Refused { why, .. }) if why.contains("load again") => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    if let Some(e) = last {
        return Err(e);
    }
    progress.message("verifying");
    let want = img.crc();
    match link.request(Command::ConfigQuery, "the verify query", REPLY)? {
        Response::PageCrc(got) if got == want => {
            Ok(Loaded { model: img.model_id().to_owned(), bytes: used, crc: want })
        }
        Response::PageCrc(got) => Err(LinkError::Verify { port: link.port().to_owned(), want, got }),
        r => Err(LinkError::Unexpected {
            port: link.port().to_owned(),
            what: "the verify query",
            reply: format!("{r:?}"),
        }),
    }
}
