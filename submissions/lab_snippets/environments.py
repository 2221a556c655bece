from gym import envs
print(envs.registry.all())

import gym

# Get NChain-v0 environment
env = gym.make('NChain-v0')

# Reset the environment
print(env.reset())

# Close the environment
env.close()
