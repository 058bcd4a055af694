"""Bundled robot descriptions (URDF files), installed as package data of ``kinplan.robots``."""
