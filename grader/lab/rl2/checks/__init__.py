"""The second lab's checks: one module per problem, the MDP calls and returned values shared in `mdp_calls`."""  # noqa: E501
