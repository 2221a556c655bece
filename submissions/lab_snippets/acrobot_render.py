import gym

# Get environment
env = gym.make("Acrobot-v1")

# Take random actions and visualize each action
try:
    env.reset()
    done = False
    while not done:
        env.render()
        obs, reward, done, info = env.step(env.action_space.sample())
        if done:
            break
finally:
    env.close()
print("done", done)
