"""Hosts on one machine, for trying "the robot here, the operator there": network namespaces joined by a switch.

:mod:`tutorial.tools.network.hosts` makes the hosts (each a Linux network
namespace with its own address and its own ``/dev/shm``), runs programs in
them and removes everything afterwards; it also puts faults on a host's link
(random loss, a partition, no multicast, a bandwidth limit).
:mod:`tutorial.tools.network.discovery` says how ROS 2 nodes on different hosts
find each other: multicast, static peers, or a Fast DDS discovery server.
:mod:`tutorial.tools.network.host_program` runs one program on a host and keeps
its output lines with the time each arrived.
Making namespaces needs root (and ``ip``, ``nft`` and ``tc``):
:func:`tutorial.tools.network.hosts.why_unavailable` says what is missing.
"""
