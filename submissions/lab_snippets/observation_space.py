import gym

env = gym.make("GuessingGame-v0")
observation = env.reset()

# Make a random guess
print(env.step(env.action_space.sample()))
