"""The tutorial's controllers, one per step (attached to bodies by project files)."""
