//! `hammerstein_wiener` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 000 eq. 15–17.

use model_core::models::hammerstein_wiener::Registered;
use model_core::Model;

use super::search::{network_layout, Scales, SearchBox, Strategy, Structure};
use super::HostModel;

impl HostModel for Registered {
    const STRUCTURE: Structure = Structure::HammersteinWiener;

    /// Trained by [`crate::ident::fit`]'s network trainer, which sets every value from the
    /// data; the box here only documents the layout.
    fn search(_s: &Scales) -> Option<SearchBox> {
        Some((network_layout(Self::PARAM_NAMES, Self::N_PARAMS), Strategy::Network))
    }
}
