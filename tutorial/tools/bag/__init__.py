"""Record and replay: ``rtt-bag``, the stand-in for ``ros2 bag`` (rosbag2 has no PyPI wheel).

It writes and reads the files rosbag2's MCAP storage plugin writes, so the
ROS 2 tools (``ros2 bag info``/``play`` with ``rosbag2_storage_mcap``) and
Foxglove open them.  One job per module:

===============  ===========================================================
``record``       :class:`BagRecorder`: subscribe raw, write each message (ROS)
``play``         :class:`BagPlayer`: republish with the recorded timing (ROS)
``info``         :func:`bag_info`: per topic type, count, time span, rate, QoS
``reader``       read without ROS: raw messages, decoded messages;
                 a file that was not closed, record by record
``series``       :func:`joint_series`: a joint's positions over a recording, as arrays
``recover``      :func:`recover`: a closed, indexed copy of a damaged or unclosed file
``writer``       the MCAP file as rosbag2 lays it out; the write-through policy
``qos``          ``offered_qos_profiles``: rosbag2's YAML and its QoS adaptations
``record_tf``    :class:`TfRecording`: ``/tf``, ``/tf_static`` from descriptions and states
===============  ===========================================================

The messages' full definitions come from :mod:`tutorial.interfaces.definitions`;
the ``rtt-bag`` command line is :mod:`tutorial.tools.rtt_bag`.

In a notebook (after ``init_ros()``)::

    from tutorial.tools.bag import BagRecorder, BagPlayer, bag_info, format_info, joint_series
    rec = BagRecorder("drive.mcap", ["/joy", "/Tank/joint_state"]).start()
    ...                                  # drive
    rec.close()
    print(format_info(bag_info("drive.mcap")))
    series = joint_series("drive.mcap")  # no ROS: numpy arrays by joint name
    BagPlayer("drive.mcap").play()       # into a running viewer

Why ``mcap`` + ``mcap-ros2-support``, not ``rosbags``
-----------------------------------------------------
Both are well kept, both read and write MCAP; compared on what a recorder needs:

* **What each writes.** ``mcap`` (Foxglove's reference Python library, the
  same project as the C++ library inside ``rosbag2_storage_mcap``) writes a
  single ``.mcap`` file with exactly the records we ask for: schemas,
  channels with any metadata, messages with separate ``log_time`` and
  ``publish_time``, metadata records; it does the chunking (zstd or lz4),
  message and chunk indexes, statistics, summary and CRCs.  ``rosbags``
  writes a rosbag2 *directory* (``metadata.yaml`` plus ``NAME/NAME.mcap``),
  not the ``FILE.mcap`` the issue asks for, through its own MCAP encoder
  that gives a message one timestamp for both times and stores no
  ``topic_type_hash``.
* **The full ``ros2msg`` definition.** rosbag2 stores the ``.msg`` files'
  text, comments included, with every dependency after a
  ``====...`` / ``MSG: pkg/Name`` line.  The ROS 2 wheels ship those
  ``.msg`` files (``<venv>/share/<pkg>/msg/``), but neither library reads
  them: ``mcap-ros2-support`` takes the text from its caller, ``rosbags``
  generates a comment-less text from its own bundled copy of each type
  (``Typestore.generate_msgdef``), which may differ from the installed
  version.  :mod:`tutorial.interfaces.definitions` builds the text as rosbag2
  does (same search, same order, same separators), from the installed files.
* **Raw CDR bytes.** Both take bytes as they are: ``mcap``'s
  ``Writer.add_message(data=...)``; ``rosbags``' ``Writer.write(conn, t, data)``.
  ``mcap-ros2-support``'s own writer only serializes Python objects, so we
  use the base ``mcap`` writer for recording.
* **Channel metadata.** ``mcap``: any ``dict[str, str]`` per channel.
  ``rosbags``: it writes ``offered_qos_profiles`` from its ``Qos`` objects,
  nothing else.
* **Reading without ROS.** ``mcap-ros2-support``'s ``DecoderFactory``
  builds the CDR deserializer from the schema text stored in the file, so
  any bag decodes with no type store and no ROS.  ``rosbags`` decodes
  types it knows or that were registered from the file's schemas.
* **A file that was not closed** (a killed recorder, a full disk).  Both
  refuse it: ``mcap``'s seeking reader raises ``EndOfFile`` (or a
  length-limit error) when the footer is missing, ``rosbags`` "File end
  magic is invalid".  ``mcap`` also has a record-level reader
  (``mcap.stream_reader.StreamReader``) that reads from the start, record by
  record; :mod:`tutorial.tools.bag.reader` uses it to read every complete chunk of
  such a file, as the ``mcap recover`` command does, and
  :mod:`tutorial.tools.bag.recover` writes what it read into a closed file.

So: ``mcap`` to write (what rosbag2 writes, in one file, by the format's
own library) and to read, ``mcap-ros2-support`` to decode without ROS.
``rosbags`` stays a test dependency: it is the second, independent stock
reader the tests open our files with.

Importing this package does not import rclpy; the names below are loaded
when first used.
"""

from __future__ import annotations

_EXPORTS = {
    "BagRecorder": "tutorial.tools.bag.record",
    "BagPlayer": "tutorial.tools.bag.play",
    "bag_info": "tutorial.tools.bag.info",
    "format_info": "tutorial.tools.bag.info",
    "BagError": "tutorial.tools.bag.reader",
    "iter_raw": "tutorial.tools.bag.reader",
    "read_messages": "tutorial.tools.bag.reader",
    "joint_series": "tutorial.tools.bag.series",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    """Load :data:`_EXPORTS` lazily, so ``from tutorial.tools.bag import joint_series`` needs no ROS."""
    if name in _EXPORTS:
        import importlib

        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'tutorial.tools.bag' has no attribute {name!r}")
