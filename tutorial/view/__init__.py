"""What a person sees: the 3D view, its overlays, the monitor's status, pictures and plots.

==================  ================================================================
module              job
==================  ================================================================
``scene``           a MuJoCo model drawn in meshcat, moved from an ``MjData``
``overlays``        arrows a controller draws over the 3D view
``meshcat_server``  a meshcat server on 127.0.0.1 that ends with its process
``meshcat_batch``   a frame's transforms as one message to that server (``set_transforms``)
``meshcat_page``    the page it serves: meshcat's own, drawing that message; lighter without a GPU
``status``          a monitor's status: rate, age of the newest state, stale or live
``images``          camera pictures received over ROS 2, and PNG files of them
``plots``           joint positions over time, received over ROS 2, and their plot
==================  ================================================================

All of it belongs to the thread that owns the view (the main thread).
"""
