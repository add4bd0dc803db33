"""Long runs lose nothing: atomic files, checksummed checkpoints, runs that resume bit for bit.

- :mod:`.atomic` — output files written whole or not at all;
- :mod:`.checkpoint` — the checkpoint file format and its checks;
- :mod:`.resumable` — core integrations that stop and resume exactly.
"""
