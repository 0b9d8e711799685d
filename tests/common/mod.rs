#![allow(dead_code)]
pub use rotorsim::verification::uniform_section as uniform;
