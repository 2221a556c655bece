"""The second lab's played problems: one module per problem (settings model and check), verified by replay."""
