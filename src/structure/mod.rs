//! Structural elements: rotations, geometrically exact beams, rigid bodies, joints, forces.
