"""Helpers of the taos documentation build. The Sphinx extension itself is :mod:`taosdocs.ext`
(imported only by Sphinx); :mod:`taosdocs.guide`, :mod:`taosdocs.reference` and
:mod:`taosdocs.layouts` need no Sphinx, so ``tests/test_docs.py`` runs without the docs extra."""
