"""``python -m obsdesign``: the command line, the same as the ``obsdesign`` console script
(two soundness trials of session 29 reached for it and found no ``__main__``)."""

from obsdesign.cli import main

if __name__ == "__main__":
    main()
