//! What a fit record says about its inference: the method, its degrees of freedom and the
//! recommendation for the number of subjects; and the clustering's design effect used to
//! correct the breakpoints' F sets.
use crate::fit::inference::{SeMethod, CR2_RECOMMENDED_BELOW};
use crate::fit::record::InferenceRecord;
use nalgebra::DMatrix;

/// Rao & Scott's mean design effect `tr(V_iid⁻¹ V)/p` (NaN when `V_iid` is singular).
pub(super) fn design_effect(v_iid: &DMatrix<f64>, v: &DMatrix<f64>) -> f64 {
    let p = v.nrows();
    if p == 0 {
        return 1.0;
    }
    match v_iid.clone().cholesky() {
        Some(c) => c.solve(v).trace() / p as f64,
        None => f64::NAN,
    }
}

/// The inference record's text for a method on `g` subjects.
pub(super) fn inference_record(
    method: SeMethod,
    g: usize,
    df_iid: f64,
    breakpoints: String,
) -> InferenceRecord {
    let recommendation = if g < 2 {
        "one subject: rows can only be treated as independent (iid); the standard errors \
         ignore that they are repeated measures of one person"
            .to_string()
    } else if g < CR2_RECOMMENDED_BELOW {
        format!(
            "{g} subjects (< {CR2_RECOMMENDED_BELOW}): CR2 with Bell–McCaffrey degrees of freedom \
             (the default here, --se cr2); CR1 with G − 1 degrees of freedom (--se cluster) \
             under-covers with few or unbalanced subjects, and the subject bootstrap is no reliable \
             reference then either"
        )
    } else {
        format!(
            "{g} subjects: CR1 (the default from {CR2_RECOMMENDED_BELOW} subjects on) is \
             adequate; CR2 (--se cr2) is the cautious choice when subjects' row counts are very \
             unbalanced"
        )
    };
    InferenceRecord {
        method: method.label().to_string(),
        description: method.describe().to_string(),
        clusters: g,
        df: match method {
            SeMethod::Iid => Some(df_iid),
            SeMethod::Cluster => Some(g as f64 - 1.0),
            SeMethod::Cr2 => None,
        },
        breakpoints,
        recommendation,
    }
}
