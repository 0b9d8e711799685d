//! Rotor deck -> multibody model.
