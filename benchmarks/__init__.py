"""Benchmarks of the tutorial's pipeline against bare MuJoCo and bare rclpy (``make bench``)."""
