"""Figures and the HTML report.

Each ``*_figures`` module draws one paper's figures with matplotlib (Agg
backend, imported inside the functions); :mod:`softbend.reports.html` assembles
them with tables into one self-contained page per run.
"""
