"""The Measure-in-JOG HMI application (FastAPI, Jinja2 + htmx)."""
