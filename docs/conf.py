"""Sphinx configuration of the taos documentation (``make docs``; built with -W, no warnings)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE / "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")

project = "taos"
author = "the taos authors"
copyright = "the taos authors, Apache-2.0"
try:
    import taos
    release = version = taos.__version__
except Exception:  # pragma: no cover - the build needs taos importable anyway
    release = version = "0.0"

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "myst_parser",
    "sphinx-mathjax-offline",   # MathJax shipped with the site: equations render without a network
    "taosdocs.ext",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
# docs/verification.md (written by the verification suite) is pulled in through
# verification_page.md when present; _generated holds what the build makes
exclude_patterns = ["_build", "_generated", "verification.md", "Thumbs.db", ".DS_Store", "gallery/*.ipynb",
                    "gallery/*.py", "gallery/*.zip"]
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_typehints_format = "short"
autodoc_preserve_defaults = True
napoleon_numpy_docstring = True
napoleon_google_docstring = False
nitpicky = False

html_theme = "alabaster"
html_title = f"taos {release}"
html_static_path: list[str] = []
html_theme_options = {"description": "TVC gimbal and actuator simulation", "page_width": "1100px",
                      "sidebar_width": "240px"}

# The examples gallery (sphinx-gallery): every examples/plot_*.py is run by the build (an error
# stops it) and shown with its output and pictures in docs/gallery (generated, not in git), every
# build (run_stale_examples: also an example unchanged since the last build's docs/gallery, whose
# output the code may have changed). The hook taosdocs.gallery.reset_example, before and after
# each example, removes the friction laws it registered and records its run for
# tests/test_examples.py (which, under make test, checks that record instead of running the
# script again; see there).
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": str(HERE / "gallery"),
    "filename_pattern": r"/plot_",
    "abort_on_example_error": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "show_signature": False,
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "within_subsection_order": "FileNameSortKey",
    "run_stale_examples": True,
    "reset_modules": ("matplotlib", "taosdocs.gallery.reset_example"),
    "reset_modules_order": "both",
}
