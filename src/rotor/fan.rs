//! Rotating natural frequencies of a rotor deck (fan plot).
