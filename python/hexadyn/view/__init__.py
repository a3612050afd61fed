"""Watch a run: a 3D animation of a results folder in the browser (``hexadyn view``), live or
exported to one self-contained HTML file. Needs the ``view`` extra (viser)."""
