"""What every command needs from the machine, and nothing of masonry: errors, signals and the exit statuses
of an interrupted run, locks on output files, guarded reads of the user's inputs, memory and time (resources,
cores, the machine's load), progress bars, the sparse Cholesky, the version.

Data passes through it only as bytes and numbers: an input is read here (``inputs.read_text``), checked against
the memory available (``inputs.fits_in_memory``), and what is written leaves under a lock (``locks.claim``).
The lowest room: it imports from no other.
"""
