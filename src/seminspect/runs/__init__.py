"""Run directories: one locked writer, a heartbeat, a truthful last status, reuse and sweeps."""
