"""Simulated events the screenshot scripts share (make_screenshots.py, make_machine_screenshot.py):
shutting the splash screen and opening the sidebar's Wire tab, for which Blender 3.4 has no API.
Each returns None, so that a timer calling it runs once."""
import os


def close_splash(win):
    x, y = win.width // 2, 40
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=y)
    win.event_simulate(type='ESC', value='PRESS', x=x, y=y)
    win.event_simulate(type='ESC', value='RELEASE', x=x, y=y)
    return None


def click_tab(win, ui):
    """Clicks "Wire" (the 4th tab) of the sidebar region `ui`, TAB_OFFSET (157) pixels below its top."""
    x, y = ui.x + ui.width - 10, ui.y + ui.height - int(os.environ.get("TAB_OFFSET", "157"))
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=y)
    win.event_simulate(type='LEFTMOUSE', value='PRESS', x=x, y=y)
    win.event_simulate(type='LEFTMOUSE', value='RELEASE', x=x, y=y)
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x - 600, y=y)
    return None
