"""A plugin whose import never returns (pdverify must list it as broken, within the plugin
time limit, and go on)."""
import time

while True:
    time.sleep(1)
