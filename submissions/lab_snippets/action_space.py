import gym

env = gym.make('NChain-v0')
env.reset()

# Determine the number of actions available
print(env.action_space)

# Reset environment and perform a random action
print(env.step(env.action_space.sample()))

# Initialize Guessing Game environment
env = gym.make("GuessingGame-v0")
observation = env.reset()
# Check size of action space
print(env.action_space.shape)

# Check range of action space
print(repr(env.action_space.high))
print(repr(env.action_space.low))
