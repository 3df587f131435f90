"""Benchmarks and stability studies: speed against accuracy, measured side by side.

``hydrofmu bench`` runs them all and writes CSV files and PNG plots (see ``run``).
"""
