"""``python -m masonryfw`` runs the command-line interface."""
from .cli import main

main()
