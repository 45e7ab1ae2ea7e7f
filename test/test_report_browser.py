"""
The report's page in a real browser: headless Chromium opens it from disk with no network.

Debian's ``chromium`` (``.ci/run`` installs it when missing; the test skips with the
reason where it is absent, unless RBD_REQUIRE_BROWSER is set, as CI sets it). WebGL
runs on SwiftShader, so the 3D views render without a GPU.
"""

import os
import shutil
import subprocess

import numpy as np
import pytest
from rigid_body_dynamics.tools import report

FLAGS = ['--headless', '--no-sandbox', '--disable-gpu', '--use-angle=swiftshader',
         '--enable-unsafe-swiftshader', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync',
         '--virtual-time-budget=8000']


def _chromium():
    found = shutil.which('chromium') or shutil.which('chromium-browser')
    if found is None:
        if os.environ.get('RBD_REQUIRE_BROWSER'):
            pytest.fail("chromium is not installed (.ci/run installs Debian's chromium)")
        pytest.skip('chromium is not installed (apt-get install chromium; .ci/run does)')
    return found


def test_report_page_renders_offline_without_console_errors(tmp_path):
    """Tennis racket: 4 plotly views with WebGL canvases, 150 animation steps, a real picture."""
    chromium = _chromium()
    out = tmp_path / 'report'
    assert report.main(['--preset', 'tennis_racket', '--duration', '30', '--dt', '0.01',
                        '--out', str(out)]) == 0
    url = (out / 'index.html').as_uri()
    profile = str(tmp_path / 'profile')
    dom = subprocess.run([chromium, *FLAGS, f'--user-data-dir={profile}',
                          '--window-size=1200,3000', '--enable-logging=stderr', '--v=0',
                          '--dump-dom', url], capture_output=True, text=True, timeout=120)
    assert dom.returncode == 0, dom.stderr[-2000:]
    console = [line for line in dom.stderr.splitlines() if ':CONSOLE' in line]
    errors = [line for line in console
              if ('error' in line.lower() or 'uncaught' in line.lower())
              and 'GL Driver Message' not in line]
    assert errors == [], errors
    html = dom.stdout
    assert html.count('js-plotly-plot') == 4 and html.count('<canvas') >= 4
    assert html.count('slider-tick-rect') == 150          # the animation's frames
    shot = tmp_path / 'shot.png'
    subprocess.run([chromium, *FLAGS, f'--user-data-dir={profile}', '--window-size=1200,2600',
                    f'--screenshot={shot}', url], capture_output=True, timeout=120, check=True)
    import matplotlib.image
    pixels = matplotlib.image.imread(str(shot))
    assert pixels.shape[0] == 2600 and pixels[..., :3].std() > 0.05       # not blank
    # the 3D views drew something where they are: the polhode area is not page-white
    assert np.mean(pixels[450:900, 300:900, :3]) < 0.97
