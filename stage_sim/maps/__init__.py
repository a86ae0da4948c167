"""The static world as grids: model geometry in world coordinates and its rasterisation at the world resolution.

Built from a :class:`~stage_sim.worldfile.description.WorldDescription`; used by the ray caster and the
collision checker. Imports only :mod:`stage_sim.worldfile`.
"""
