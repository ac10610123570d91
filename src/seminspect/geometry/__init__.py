"""Pure geometry: poses, rotations, validation of metric inputs. No I/O, no state."""
