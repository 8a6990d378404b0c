"""Step 1's lesson: the Joy callback and control() share the newest message under one lock."""

import threading
from types import SimpleNamespace

from tutorial.controllers.tank_controller import RttTankController


def test_control_always_sees_one_whole_message_under_concurrent_callbacks():
    controller = RttTankController()
    errors: list[BaseException] = []
    stop = threading.Event()
    torn = []

    def publisher(offset: int) -> None:
        try:
            k = offset
            while not stop.is_set():
                # every value of message k is k: a torn read would mix two k's
                controller.on_joy(SimpleNamespace(axes=[float(k)] * 8, buttons=[k] * 8))
                k += 4
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)

    def control_loop() -> None:
        try:
            for _ in range(20000):
                _count, axes, buttons = controller.take_input()
                if axes and (set(axes) != {float(buttons[0])} or set(buttons) != {buttons[0]}):
                    torn.append((axes, buttons))
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)

    threads = [threading.Thread(target=publisher, args=(i,)) for i in range(4)]
    reader = threading.Thread(target=control_loop)
    for t in threads:
        t.start()
    reader.start()
    reader.join(60)
    stop.set()
    for t in threads:
        t.join(10)
    assert not reader.is_alive() and not any(t.is_alive() for t in threads)
    assert errors == []
    assert torn == []
    assert controller.summary()["joy_received"] > 0
