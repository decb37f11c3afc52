//! `hil-sim export PARAMS.json --out config.bin`: the firmware's configuration page.

use std::path::PathBuf;

use clap::Args;
use hil_sim::io::config_page;
use hil_sim::io::params_file::ParamsFile;
use serde_json::json;

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// Parameter file (`fit --save DIR` writes one per model).
    pub params: PathBuf,
    /// Where to write the page (2048 bytes).
    #[arg(long)]
    pub out: PathBuf,
    /// Control-step rate, Hz (the model's time step is its inverse). The firmware runs each
    /// model at one rate (`firmware::runner`), used when this is not given; another is refused.
    #[arg(long)]
    pub control_hz: Option<f32>,
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: ExportArgs) -> anyhow::Result<()> {
    let path = super::file_arg(&a.params)?;
    let file = ParamsFile::read(&path)?;
    // The delays align a recording's channels; the board samples its sensors itself.
    for (name, d) in [("delay_s", file.delay_s), ("command_delay_s", file.command_delay_s)] {
        if let Some(d) = d.filter(|d| *d != 0.0) {
            eprintln!(
                "warning: {}: `{name}` = {:.3} ms aligns the recording's channels and is not part of the \
                 configuration page",
                path.display(),
                1e3 * d
            );
        }
    }
    let (control_hz, control) = config_page::firmware_control(&file.model, a.control_hz)?;
    let img = config_page::firmware_image(&file, &path, control)?;
    // The board's physics check of the page (and the set's channels): a page it would
    // refuse is not written.
    hil_sim::io::page_physics::check(&file, &path, &img)?;
    let bytes = img.encode();
    hil_sim::io::output::write(&a.out, bytes)?;
    let len = u16::from_le_bytes([bytes[6], bytes[7]]);
    let crc = u32::from_le_bytes([
        bytes[usize::from(len)],
        bytes[usize::from(len) + 1],
        bytes[usize::from(len) + 2],
        bytes[usize::from(len) + 3],
    ]);
    if a.json {
        super::print_json(&json!({
            "out": a.out, "model": img.model_id(), "n_params": img.params().len(),
            "bytes": bytes.len(), "crc_covered_bytes": len, "crc": format!("{crc:#010x}"),
            "control_hz": control_hz,
        }))
    } else {
        super::emit(&format!(
            "{}: {} ({} parameters), {} bytes, CRC-32 {crc:#010x} over {len} bytes; the board runs it at {control_hz} Hz\n",
            a.out.display(),
            img.model_id(),
            img.params().len(),
            bytes.len()
        ));
        Ok(())
    }
}
