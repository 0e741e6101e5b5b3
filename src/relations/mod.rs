//! The published relations, one type per relation (one file each), behind one trait.
