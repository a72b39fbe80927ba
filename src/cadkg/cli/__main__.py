"""``python -m cadkg.cli``: the ``cadkg`` command."""

from cadkg.cli import main

main()
