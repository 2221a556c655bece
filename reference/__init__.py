"""Reference solutions and exact oracles for the OpenGym AI lab."""
