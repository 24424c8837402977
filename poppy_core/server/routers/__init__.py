"""The routers of the server: pypot's routes and the v1 API, one module per resource."""
