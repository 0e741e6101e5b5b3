//! The fit form of `kb-mu` (Ko & Badler 1993, appendix A, eqs. 21–24): the linear α and μ* are
//! fitted in the raw basis; sl* and ll(S*) are held.
use super::{Form, Plan};
use crate::relations::kb_mu::{LL_STAR, NAMES, SL_STAR};
use crate::relations::{Observation, Relation};

/// The form of [`crate::relations::KbMu`].
#[derive(Debug, Clone, Copy)]
pub struct MuForm;

impl Form for MuForm {
    /// sl* is not identifiable beside free intercepts μ*, and ll(S*) defines the argument x.
    fn plan(&self, _rel: &dyn Relation, _obs: &[Observation]) -> Plan {
        let mut held = vec![None; NAMES.len()];
        held[SL_STAR] = Some(
            "held at the bundled prototype's step length: not identifiable beside free μ*".into(),
        );
        held[LL_STAR] =
            Some("held at Winter's leg length as the trials tables measure it (defines x)".into());
        Plan {
            held,
            search: vec![None; NAMES.len()],
        }
    }
}
