"""What a person sees: the 3D view, its overlays, the monitor's status, pictures and plots.

====================  ================================================================
module                job
====================  ================================================================
``scene``             a MuJoCo model drawn in meshcat, moved from an ``MjData``
``meshcat_overlays``  arrows a controller draws over the 3D view
``meshcat_batch``     a frame's transforms as one message (``set_transforms``)
``meshcat_page``      the page that draws it: meshcat's own; lighter without a GPU
``widget/``           the same scene as a Jupyter widget, over the notebook's own connection
``status``            a monitor's status: rate, age of the newest state, stale or live
``images``            camera pictures received over ROS 2
``joint_plot``        joint positions over time, received over ROS 2, and their plot
====================  ================================================================

A scene belongs to the thread that owns its view (a run's owner thread).  What
arrives from elsewhere says so in its module: a subscription's callback on the
spin thread (``status``, ``images``, ``joint_plot``), a browser's message on the
kernel's thread (``widget``); each takes a lock, named beside it.
"""
