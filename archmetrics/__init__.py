"""archmetrics: how much it costs to integrate new code into an existing system."""

__version__ = "0.1.0"
