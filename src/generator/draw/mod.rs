//! The drawing layer (issue 20, Build item 2): a generator's simulated tracks become frames
//! through task-space curves and one soft leg IK, so that the drawn motion is continuous by
//! construction instead of by scans and eases.
//!
//! - [`track`]: C² curves through keys (value, rate, acceleration at each knot, one quintic
//!   Hermite segment between knots), and keys through samples from a cubic spline, with ends
//!   that may be held at rest: a planted coordinate is *exactly* constant between two keys at
//!   rest with equal values.
//! - [`foot`]: the rolling foot as one roll coordinate about its heel, metatarsal joint and toe
//!   tip, twice differentiable away from the flat foot, and the stance roll curve that is
//!   exactly flat between foot flat and heel off and at rest at both ends of the flat foot.
//! - [`feet`]: a foot's whole drawn path from sampled targets: contact runs rolling, flights
//!   splined and corrected onto the rolling foot at both ends.
//! - [`leg`]: the one soft two-link leg IK: the hip–ankle distance is softened near full
//!   extension (C², straight only in the limit), then the rigid chain is solved inside its reach.
//!
//! A drawn coordinate is then a C² curve of time, and a joint angle a smooth function of C²
//! task-space curves: its frame-to-frame steps vary smoothly at any frame rate. The paper's true
//! discontinuities (the knee lock, the heel-strike impulse) are smoothed once, by the spacing of
//! the keys ([`track::spline_keys`] samples a simulated track at knots, not at every integrator
//! step).
pub mod feet;
pub mod foot;
pub mod leg;
pub mod track;
