//! The [`Motion`] type shared by every generator.
