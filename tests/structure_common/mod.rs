#![allow(dead_code)]
pub use rotorsim::solver::verification::uniform_section as uniform;
