"""
The report's interactive views: rotatable 3D figures and the tumbling body, with plotly.

Made with plotly's Python package, which ships plotly.js: ``plotly.min.js`` is
written beside index.html (no CDN, works from disk without a network). Views:
the polhode on the inertia ellipsoid (body frame), the herpolhode on the
invariant plane (world frame), the momentum sphere (body frame, from
physics/analysis/momentum_sphere.py), and an animation of the body: the uniform box
with the body's principal moments (physics.inertia.equivalent_box), its body
axes and the omega and L arrows in the world frame, beside omega(t) with a
marker at the frame's time, with a slider and play button.
"""

import os

import numpy as np

from ..physics import quaternions
from ..physics.analysis import estimators, momentum_sphere, poinsot
from ..physics.inertia import equivalent_box

#: Frames of the animation (evenly spaced samples of the run).
FRAMES = 150
#: Most samples of a run drawn as a curve on the page (a finer run is thinned evenly).
MAX_POINTS = 3000
_BOX_FACES = np.array([[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6], [0, 4, 5], [0, 5, 1],
                       [1, 5, 6], [1, 6, 2], [2, 6, 7], [2, 7, 3], [3, 7, 4], [3, 4, 0]])


def box_vertices(moments):
    """Return the 8 corners (body frame, m) of the equivalent box, in _BOX_FACES' order."""
    a, b, c = equivalent_box(moments) / 2.0
    return np.array([[-a, -b, -c], [a, -b, -c], [a, b, -c], [-a, b, -c],
                     [-a, -b, c], [a, -b, c], [a, b, c], [-a, b, c]])


def _line(points, name, color, width=4, dash=None):
    import plotly.graph_objects as go
    return go.Scatter3d(x=points[:, 0], y=points[:, 1], z=points[:, 2], mode='lines', name=name,
                        line={'color': color, 'width': width, 'dash': dash})


def views(moments, t, q, w):
    """
    Make the plotly figures of a run: principal ``moments``, ``q`` (N, 4), ``w`` (N, 3).

    Returns {name: figure}; each figure's data are the arrays drawn (tests read them).
    A run of more than MAX_POINTS samples is thinned evenly for the page.
    """
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots
    moments = np.asarray(moments, dtype=float)
    stride = max(1, -(-len(t) // MAX_POINTS))
    t, q, w = t[::stride], q[::stride], w[::stride]
    l_body = moments * w
    geometry = poinsot.construction(moments, q[0], w[0])
    out = {}
    fig = go.Figure([go.Surface(x=x, y=y, z=z, opacity=0.25, showscale=False,
                                colorscale='Greys', name='inertia ellipsoid')
                     for x, y, z in [poinsot.ellipsoid_surface(geometry.semi_axes)]])
    fig.add_trace(_line(w, 'polhode (omega, body frame)', 'crimson'))
    fig.update_layout(title='Polhode on the inertia ellipsoid omega.I.omega = 2T (body frame)',
                      scene_aspectmode='data')
    out['polhode'] = fig

    w_world = quaternions.rotate(q, w)
    normal, d = geometry.normal, geometry.distance
    e1, e2, _ = estimators.basis_perpendicular(normal)
    r = 1.2 * float(np.max(np.linalg.norm(w_world - d * normal, axis=1))) + 1e-12
    s, u = np.meshgrid(np.linspace(-r, r, 2), np.linspace(-r, r, 2))
    plane = d * normal[:, None, None] + e1[:, None, None] * s + e2[:, None, None] * u
    fig = go.Figure([go.Surface(x=plane[0], y=plane[1], z=plane[2], opacity=0.25,
                                showscale=False, colorscale='Blues', name='invariant plane'),
                     _line(w_world, 'herpolhode (omega, world frame)', 'purple')])
    fig.update_layout(title='Herpolhode on the invariant plane omega.L/|L| = 2T/|L| '
                      '(world frame)', scene_aspectmode='data')
    out['herpolhode'] = fig

    l0 = float(np.linalg.norm(l_body[0]))
    x, y, z = poinsot.ellipsoid_surface((l0, l0, l0))
    fig = go.Figure([go.Surface(x=x, y=y, z=z, opacity=0.15, showscale=False,
                                colorscale='Greys', name='|L| = |L0|')])
    family = momentum_sphere.curve_family(moments, l0)
    for key, color, width in (('major', 'royalblue', 2), ('minor', 'seagreen', 2),
                              ('separatrix', 'red', 6)):
        for k, c in enumerate(family[key]):
            fig.add_trace(_line(c, f'{key} {k}', color, width))
    fig.add_trace(_line(l_body, 'this run', 'black', 5))
    fig.update_layout(title='Momentum sphere: L runs along its intersection with the energy '
                      'ellipsoid (body frame; red: the separatrix)', showlegend=False,
                      scene_aspectmode='data')
    out['momentum sphere'] = fig

    out['tumbling body'] = _animation(moments, t, q, w, quaternions.rotate(q, l_body),
                                      make_subplots, go)
    return out


def _animation(moments, t, q, w, l_world, make_subplots, go):
    """Animate the box tumbling in the world frame beside omega(t), FRAMES frames."""
    pick = np.unique(np.linspace(0, len(t) - 1, min(FRAMES, len(t))).round().astype(int))
    corners = box_vertices(moments)
    size = float(np.max(np.abs(corners))) * 1.6
    w_scale = size / max(float(np.max(np.linalg.norm(w, axis=1))), 1e-12)
    l_scale = size / max(float(np.max(np.linalg.norm(l_world, axis=1))), 1e-12)

    def traces(k):
        box = quaternions.rotate(np.repeat(q[k][None, :], 8, axis=0), corners)
        axes = quaternions.rotate(np.repeat(q[k][None, :], 3, axis=0), np.eye(3) * size)
        omega = quaternions.rotate(q[k][None, :], w[k][None, :])[0] * w_scale
        lw = l_world[k] * l_scale
        data = [go.Mesh3d(x=box[:, 0], y=box[:, 1], z=box[:, 2], i=_BOX_FACES[:, 0],
                          j=_BOX_FACES[:, 1], k=_BOX_FACES[:, 2], color='lightsteelblue',
                          opacity=0.8, flatshading=True, name='body')]
        for n, (axis, color) in enumerate(zip(axes, ('red', 'green', 'blue'))):
            seg = np.stack([np.zeros(3), axis])
            data.append(go.Scatter3d(x=seg[:, 0], y=seg[:, 1], z=seg[:, 2], mode='lines',
                                     line={'color': color, 'width': 5},
                                     name=f'body axis {n + 1}'))
        for vec, name, color in ((omega, 'omega', 'orange'), (lw, 'L', 'black')):
            seg = np.stack([np.zeros(3), vec])
            data.append(go.Scatter3d(x=seg[:, 0], y=seg[:, 1], z=seg[:, 2], mode='lines',
                                     line={'color': color, 'width': 8}, name=name))
        data.append(go.Scatter(x=[t[k]] * 3, y=list(w[k]), mode='markers',
                               marker={'size': 9, 'color': 'black'}, name='now'))
        return data
    fig = make_subplots(rows=1, cols=2, column_widths=[0.55, 0.45],
                        specs=[[{'type': 'scene'}, {'type': 'xy'}]])
    for trace in traces(pick[0]):
        fig.add_trace(trace, row=1, col=1 if not isinstance(trace, go.Scatter) else 2)
    for i, color in enumerate(('red', 'green', 'blue')):
        fig.add_trace(go.Scatter(x=t, y=w[:, i], mode='lines', line={'color': color},
                                 name=f'omega_{i + 1}'), row=1, col=2)
    moving = list(range(7))
    fig.frames = [go.Frame(data=traces(k), traces=moving, name=f'{t[k]:.3f}') for k in pick]
    lim = [-1.1 * size, 1.1 * size]
    fig.update_layout(
        title='The body tumbling in the world frame (box with its principal moments; '
              'omega orange, L black) beside omega(t), body frame',
        scene={'xaxis': {'range': lim}, 'yaxis': {'range': lim}, 'zaxis': {'range': lim},
               'aspectmode': 'cube'},
        updatemenus=[{'type': 'buttons', 'showactive': False, 'buttons': [
            {'label': 'play', 'method': 'animate',
             'args': [None, {'frame': {'duration': 60, 'redraw': True}, 'fromcurrent': True}]},
            {'label': 'pause', 'method': 'animate',
             'args': [[None], {'frame': {'duration': 0}, 'mode': 'immediate'}]}]}],
        sliders=[{'currentvalue': {'prefix': 't = ', 'suffix': ' s'}, 'steps': [
            {'label': f.name, 'method': 'animate',
             'args': [[f.name], {'frame': {'duration': 0, 'redraw': True},
                                 'mode': 'immediate'}]} for f in fig.frames]}])
    return fig


def write(out_dir, figures):
    """Write plotly.min.js beside the page; return the HTML of the figures' divs."""
    from plotly.offline import get_plotlyjs
    with open(os.path.join(out_dir, 'plotly.min.js'), 'w', encoding='utf-8') as f:
        f.write(get_plotlyjs())
    parts = []
    for name, fig in figures.items():
        fig.update_layout(height=650 if name == 'tumbling body' else 550)
        parts.append(f'<h2>{name}</h2>\n' + fig.to_html(full_html=False, include_plotlyjs=False,
                                                        auto_play=False))
    return '\n'.join(parts)
