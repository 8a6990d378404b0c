"""The experiments of ``make bench``, a module each: every one returns its figures as a dict for ``latest.json``.

* :mod:`.speed`: the simulation on its own, as fast as possible against bare ``mj_step``, and in real time;
* :mod:`.cross_process`: simulation and viewer as two processes against the bare rclpy pair;
* :mod:`.scene_update`: meshcat's cost per frame, one message against a round trip per body;
* :mod:`.startup`: from the launch command to the first state shown;
* :mod:`.scale`: the pipeline as the tanks and the joints grow;
* :mod:`.browser`: from a published state to the pixel in a real browser, against a bare meshcat page;
* :mod:`.page_cost`: what one frame of the meshcat page costs the browser, and where its main thread waits
  (run on its own, not by ``make bench``).
"""
