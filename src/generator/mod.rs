//! Motion generators and the figure they animate: one skeleton and one [`motion::Motion`] type
//! shared by the running (RUNNER), walking (KLAW) and generalization (Ko–Badler) generators.
pub mod anthropometry;
pub mod checks;
pub mod curves;
pub mod draw;
pub mod generalize;
pub mod ik;
pub mod motion;
pub mod numeric;
pub mod running;
pub mod schedule;
pub mod skeleton;
pub mod walking;

use thiserror::Error;

/// Errors of the generators.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum GenerateError {
    /// A parameter is outside its anatomical or numerical limits.
    #[error("parameter {name} = {value}: {message}")]
    Parameter {
        /// Parameter or attribute name.
        name: String,
        /// The value given.
        value: f64,
        /// The accepted range and why.
        message: String,
    },
    /// A numerical procedure (shooting, Newton–Raphson, IK) failed.
    #[error("{stage}: {message}")]
    Numerical {
        /// Which stage (e.g. "step 3, swing2 shooting").
        stage: String,
        /// Details.
        message: String,
    },
    /// An input file of a generator (e.g. a per-step schedule) is unreadable or malformed.
    #[error("{path}: {message}")]
    Input {
        /// The file.
        path: String,
        /// Where (row, column) and what is wrong, and the remedy.
        message: String,
    },
}
