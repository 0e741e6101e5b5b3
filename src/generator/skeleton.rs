//! The figure: skeleton and anthropometry scaled from body height.
