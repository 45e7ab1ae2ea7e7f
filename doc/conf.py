"""
Sphinx configuration of the manual (the layout rosdoc2 expects: doc/conf.py, doc/index).

Build: ``./dev docs`` (HTML in build/doc/html, warnings are errors). Only the
extensions rosdoc2 allows: sphinx.ext.* and myst_parser. Math renders offline:
when the ``sphinx-mathjax-offline`` package is installed (requirements/common.txt),
its self-contained MathJax 3 (SVG output, every TeX extension built in, no fonts
or extensions fetched) is copied beside the pages, so the manual works from
disk with no network; elsewhere (rosdoc2 on docs.ros.org) Sphinx's default applies.
"""

import importlib.metadata
import os
import shutil
import sys
from xml.etree import ElementTree

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))
sys.path.insert(0, ROOT)

project = 'rigid_body_dynamics'
author = 'rigid_body_dynamics maintainers'
copyright = '2026, rigid_body_dynamics maintainers'  # noqa: A001 (Sphinx's name)
# the version is package.xml's, as colcon and rosdoc2 read it
release = version = ElementTree.parse(os.path.join(ROOT, 'package.xml')).findtext('version')

extensions = [
    'myst_parser',
    'sphinx.ext.autodoc',
    'sphinx.ext.napoleon',
    'sphinx.ext.mathjax',
    'sphinx.ext.intersphinx',
    'sphinx.ext.viewcode',
]
source_suffix = {'.rst': 'restructuredtext', '.md': 'markdown'}
root_doc = 'index'
exclude_patterns = ['_build', 'reference/generated/*', 'examples/*', 'generate.py']
myst_enable_extensions = ['dollarmath', 'amsmath', 'colon_fence', 'deflist']
myst_heading_anchors = 3
autodoc_member_order = 'bysource'
autodoc_typehints = 'none'
# offline: no inventory is fetched (an empty mapping; rosdoc2 adds its own online)
intersphinx_mapping = {}
html_theme = 'sphinx_rtd_theme'
html_static_path = ['_static']
html_css_files = ['custom.css']
html_title = 'rigid_body_dynamics manual'
nitpicky = False
# The docstrings write norms as |L|, |omega|, ...: plain text there, substitutions to
# reStructuredText; these keep them as written.
rst_prolog = '\n'.join(f'.. |{name}| replace:: \\|{name}\\|'
                       for name in ('L', 'Omega', 'omega', 'omega_3', 'tau', 'theta'))

MATHJAX_FILE = 'tex-svg-full.js'


def _offline_mathjax():
    """Return the path of the packaged MathJax 3 file, or None where it is not installed."""
    try:
        dist = importlib.metadata.distribution('sphinx-mathjax-offline')
    except importlib.metadata.PackageNotFoundError:
        return None
    path = dist.locate_file(f'sphinx-mathjax-offline/static/mathjax/{MATHJAX_FILE}')
    return str(path) if os.path.exists(str(path)) else None


_MATHJAX = _offline_mathjax()
if _MATHJAX:
    mathjax_path = f'mathjax/{MATHJAX_FILE}'


def _copy_mathjax(app, exception):
    if exception is None and _MATHJAX and app.builder.format == 'html':
        target = os.path.join(app.outdir, '_static', 'mathjax')
        os.makedirs(target, exist_ok=True)
        shutil.copy(_MATHJAX, target)


def setup(app):
    """Copy the offline MathJax beside the pages after an HTML build."""
    app.connect('build-finished', _copy_mathjax)
