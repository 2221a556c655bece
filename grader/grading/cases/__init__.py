"""Acceptance tests run by the gymgrade pytest plugin: one module per problem of the lab."""
