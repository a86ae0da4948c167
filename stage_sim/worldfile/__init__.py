"""Stage's world-file language and the files a world refers to, read into a typed world description.

``.world``/``.inc`` text → tokens (:mod:`.lexer`) → syntax tree with positions (:mod:`.syntax`) →
``include``/``define`` resolved and keys checked (:mod:`.loader`, :mod:`.keys`, :mod:`.sensors`) →
:class:`~stage_sim.worldfile.description.WorldDescription`. Bitmaps and map_server YAML maps that a world
names are read here too (:mod:`.bitmap`, :mod:`.map_yaml`), so a missing or broken file is reported at the
line that names it. The bottom layer: it imports nothing else of stage_sim.
"""
