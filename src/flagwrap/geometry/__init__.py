"""Initial shapes and frame algebra (parallel transport, rotations)."""
