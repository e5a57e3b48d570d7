//! Stability matrix: stiff and extreme cases for the physics.
