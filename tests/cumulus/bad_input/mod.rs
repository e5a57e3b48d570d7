//! Bad input: malformed files and absurd arguments through the real binary,
//! and proptest fuzzing of the readers down to the physics.

mod cli;
mod fuzz;
mod outputs;
