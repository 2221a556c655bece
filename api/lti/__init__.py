"""The service as an LTI 1.3 Advantage tool: keys, registration, launch, grades, roster, deep linking."""
