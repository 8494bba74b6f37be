"""Steady whirling states, their linear stability and the critical Machin number from it
(docs/stability.md): :mod:`.steady` (Newton in the turning frame), :mod:`.spectrum`
(eigenvalues), :mod:`.threshold` (continuation in M to the first loss of stability)."""
