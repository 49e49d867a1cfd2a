"""``python -m companion`` runs the command line (``launch``: a plain ``run`` at once)."""

from companion.launch import main

main()
