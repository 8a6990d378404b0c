"""Live 3D views over the notebook's own connection: a meshcat scene as a Jupyter widget.

==============  ================================================================================
module          job
==============  ================================================================================
``widget``      :class:`MeshcatWidget` (an anywidget whose view is meshcat's own page) and its meshcat window
``flow``        :class:`FrameFlow`: coalescing, a window of frames in flight, the scene kept for views that open
                later
``subshell``    :class:`ViewSubshell`: the kernel subshell that answers views, and reloaded pages, while a cell
                runs
``nodelay``     a Jupyter server extension: the kernel's WebSocket sends each message at once (``TCP_NODELAY``)
==============  ================================================================================

``widget.js`` is the browser's side.
"""
